"""PyBullet shapes and welded bodies from SDF collision shapes, for the physics (``world_bodies``) and for what
cameras see (``render_scene``): one place that turns a ``Shape`` into a PyBullet shape."""
import os
from typing import Optional, Sequence, Tuple

import numpy as np
import pybullet

from .geometry import IDENTITY, Pose
from .log import get_logger, warn_once
from .description.world_description import Shape

_log = get_logger(__name__)

# PyBullet's createCollisionShape limits for mesh data passed as arrays.
_BULLET_MAX_MESH_VERTICES = 131072
_BULLET_MAX_MESH_INDICES = 524288
# Colour of world collisions whose link has no material (Gazebo draws those white-grey).
DEFAULT_WORLD_RGBA = (0.7, 0.7, 0.7, 1.0)


def collision_shape(client, shape: Shape, concave: bool, frame: Optional[Pose] = None) -> Optional[int]:
    """The PyBullet collision shape of ``shape``, placed at ``frame`` in its body's frame (None: at the origin);
    None when PyBullet cannot hold the mesh (with one warning)."""
    placed = {} if frame is None else dict(collisionFramePosition=frame.position,
                                           collisionFrameOrientation=frame.orientation)
    if shape.kind == "plane":
        return client.createCollisionShape(pybullet.GEOM_PLANE, planeNormal=shape.normal, **placed)
    if shape.kind != "mesh":
        geometry, size = _primitive(shape, length_key="height")
        return client.createCollisionShape(geometry, **size, **placed)
    vertices, triangles = shape.mesh.vertices, shape.mesh.triangles
    if len(vertices) > _BULLET_MAX_MESH_VERTICES or (concave and triangles.size > _BULLET_MAX_MESH_INDICES):
        warn_once(_log, f"{shape.mesh_path}: {len(vertices)} vertices and {len(triangles)} triangles exceed "
                        f"PyBullet's mesh limits ({_BULLET_MAX_MESH_VERTICES}, {_BULLET_MAX_MESH_INDICES // 3}); "
                        f"collision '{shape.name}' of model '{shape.model}' skipped")
        return None
    if concave:  # a triangle mesh, as ODE collides it, works in Bullet only for bodies that never move
        return client.createCollisionShape(pybullet.GEOM_MESH, vertices=vertices.tolist(),
                                           indices=triangles.ravel().tolist(), **placed)
    return client.createCollisionShape(pybullet.GEOM_MESH, vertices=vertices.tolist(), **placed)  # convex hull


def visual_shape(client, shape: Shape, folder: str) -> Optional[int]:
    """A visual-only twin of ``shape`` in its material colour (or Gazebo's grey); a mesh is written to an OBJ
    in ``folder`` because PyBullet's visual meshes come only from files. None for a mesh that failed to read."""
    rgba = list(shape.rgba or DEFAULT_WORLD_RGBA)
    if shape.kind == "plane":
        # A thin box of the plane's visual size, its top face on the plane.
        normal = np.asarray(shape.normal, dtype=float) / np.linalg.norm(shape.normal)
        axis = np.cross((0.0, 0.0, 1.0), normal)
        angle = np.arctan2(np.linalg.norm(axis), normal[2])
        rotation = (tuple(np.append(axis / np.linalg.norm(axis) * np.sin(angle / 2), np.cos(angle / 2)))
                    if np.linalg.norm(axis) > 1e-9 else IDENTITY.orientation)
        sx, sy = (size if size > 0 else 100.0 for size in shape.size[:2])
        return client.createVisualShape(pybullet.GEOM_BOX, halfExtents=[sx / 2, sy / 2, 0.0005], rgbaColor=rgba,
                                        visualFramePosition=tuple(-0.0005 * normal),
                                        visualFrameOrientation=rotation)
    if shape.kind != "mesh":
        geometry, size = _primitive(shape, length_key="length")
        return client.createVisualShape(geometry, **size, rgbaColor=rgba)
    if shape.mesh is None:
        return None
    path = os.path.join(folder, f"{id(shape)}.obj")
    with open(path, "w") as obj:
        np.savetxt(obj, shape.mesh.vertices, fmt="v %.6f %.6f %.6f")
        np.savetxt(obj, shape.mesh.triangles + 1, fmt="f %d %d %d")
    return client.createVisualShape(pybullet.GEOM_MESH, fileName=path, rgbaColor=rgba)


def _primitive(shape: Shape, length_key: str) -> Tuple[int, dict]:
    # PyBullet names a cylinder's length "height" for collisions and "length" for visuals.
    if shape.kind == "box":
        return pybullet.GEOM_BOX, dict(halfExtents=[s / 2.0 for s in shape.size])
    if shape.kind == "cylinder":
        return pybullet.GEOM_CYLINDER, {"radius": shape.radius, length_key: shape.length}
    if shape.kind == "sphere":
        return pybullet.GEOM_SPHERE, dict(radius=shape.radius)
    raise ValueError(f"not a primitive shape kind: {shape.kind}")


def welded_body(client, pose: Pose, parts: Sequence[Tuple[int, Pose]], visual: bool, mass: float = 0.0,
                inertial_frame: Pose = IDENTITY) -> int:
    """One multibody at ``pose``: a shapeless base carrying ``mass`` and each (shape, frame in the body) of
    ``parts`` as a massless child on a fixed joint; the shapes are visual ones when ``visual``, else collisions."""
    count = len(parts)
    shapes, frames = [shape for shape, _ in parts], [frame for _, frame in parts]
    none = [-1] * count
    return client.createMultiBody(
        baseMass=mass, baseCollisionShapeIndex=-1, baseVisualShapeIndex=-1, basePosition=pose.position,
        baseOrientation=pose.orientation, baseInertialFramePosition=inertial_frame.position,
        baseInertialFrameOrientation=inertial_frame.orientation,
        linkMasses=[0.0] * count, linkCollisionShapeIndices=none if visual else shapes,
        linkVisualShapeIndices=shapes if visual else none,
        linkPositions=[frame.position for frame in frames], linkOrientations=[frame.orientation for frame in frames],
        linkInertialFramePositions=[IDENTITY.position] * count,
        linkInertialFrameOrientations=[IDENTITY.orientation] * count,
        linkParentIndices=[0] * count, linkJointTypes=[pybullet.JOINT_FIXED] * count,
        linkJointAxis=[(0.0, 0.0, 1.0)] * count)
