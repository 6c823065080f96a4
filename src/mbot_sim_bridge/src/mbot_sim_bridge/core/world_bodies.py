"""Bodies in PyBullet for an SDF world description (see ``sdf_world``).

Each model becomes one PyBullet multibody: a base that carries the model's mass and every collision as a
massless child on a fixed joint. A static model gets mass 0, which PyBullet treats as immovable. SDF
joints are not simulated, so the links of one model move as one rigid body.
"""
from dataclasses import dataclass
from typing import Dict, Optional, Tuple

import numpy as np

from .geometry import IDENTITY, Pose, compose, inverse, rotation_matrix
from .log import get_logger, warn_once
from .pybullet_shapes import collision_shape, welded_body
from .description.world_description import ModelDescription, PhysicsConfig, Shape, WorldDescription

_log = get_logger(__name__)


@dataclass(frozen=True)
class LoadedWorld:
    physics: PhysicsConfig
    bodies: Dict[str, int]  # model name -> PyBullet body id
    shapes: Tuple[Shape, ...]  # the collisions that became PyBullet shapes
    # model name -> the body's centre-of-mass frame in the model frame; PyBullet reports base poses in it
    inertial_frames: Dict[str, Pose]

    def model_pose(self, client, name: str) -> Pose:
        """World pose of the model frame of ``name`` now."""
        position, orientation = client.getBasePositionAndOrientation(self.bodies[name])
        return compose(Pose(tuple(position), tuple(orientation)), inverse(self.inertial_frames[name]))


def world_lateral_friction(mu: float, mu2: float) -> float:
    """PyBullet ``lateralFriction`` for a world collision with SDF ``<ode><mu>``/``<mu2>``.

    ODE takes min(μa, μb) per contact; Bullet multiplies the two bodies' frictions. With the world side at
    min(μ, μ2, 1) the product equals ODE's value whenever the robot's μ is 1 (the SDF default) or the world's
    is at least 1 (the ground plane's 100) and the robot's at most 1. When both are below 1 the product is
    smaller than ODE's min. Bullet's friction is isotropic, so the smaller of μ and μ2 is used.
    """
    return min(mu, mu2, 1.0)


def load_world(client, description: WorldDescription) -> LoadedWorld:
    """Build one body per model of ``description`` in ``client`` (a BulletClient).

    Gravity and time step stay with the caller (the Engine applies ``description.physics``).
    """
    bodies, shapes, inertial_frames = {}, [], {}
    for model in description.models:
        # A static model of one collision becomes a single static object: Bullet steps it as such, where a
        # multibody with a child link costs time every step (a world of 5,000 boxes steps about 3 times faster).
        # Its collision sits at its pose in the model frame, so the body's frame stays the model's.
        single = model.static and len(model.shapes) == 1
        frame = compose(inverse(model.pose), model.shapes[0].pose) if single else None
        collision_shapes = [(shape, collision_shape(client, shape, model.static, frame)) for shape in model.shapes]
        collision_shapes = [(shape, index) for shape, index in collision_shapes if index is not None]
        if not collision_shapes:
            _log.debug(f"model '{model.name}' has no collision shape; no body created")
            continue
        if single:
            body = client.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=collision_shapes[0][1],
                                          basePosition=model.pose.position, baseOrientation=model.pose.orientation)
            inertial_frames[model.name], links = IDENTITY, (-1,)
        else:
            body, inertial_frames[model.name] = _create_body(client, model, collision_shapes)
            links = range(len(collision_shapes))
        bodies[model.name] = body
        for link, (shape, _) in zip(links, collision_shapes):
            client.changeDynamics(body, link, lateralFriction=world_lateral_friction(shape.mu, shape.mu2),
                                  restitution=0.0)
            if shape.rgba is not None:  # only the simulator window shows it
                client.changeVisualShape(body, link, rgbaColor=shape.rgba)
        shapes.extend(shape for shape, _ in collision_shapes)
    return LoadedWorld(description.physics, bodies, tuple(shapes), inertial_frames)


def _create_body(client, model: ModelDescription, collision_shapes) -> Tuple[int, Pose]:
    world_to_model = inverse(model.pose)
    mass, inertial_frame, moments = (0.0, IDENTITY, None) if model.static else _mass_properties(model)
    if not model.static and mass == 0.0:
        warn_once(_log, f"model '{model.name}' is not static but has no mass; PyBullet keeps it fixed")
    parts = [(index, compose(world_to_model, shape.pose)) for shape, index in collision_shapes]
    body = welded_body(client, model.pose, parts, visual=False, mass=mass, inertial_frame=inertial_frame)
    if moments is not None:
        client.changeDynamics(body, -1, localInertiaDiagonal=moments)
    return body, inertial_frame


def _mass_properties(model: ModelDescription) -> Tuple[float, Pose, Optional[Tuple[float, float, float]]]:
    """Total mass, principal centre-of-mass frame (in the model frame) and principal moments of the welded links."""
    world_to_model = inverse(model.pose)
    frames = [compose(world_to_model, compose(link.pose, link.inertial_pose)) for link in model.links]
    masses = np.array([link.mass for link in model.links])
    total = float(masses.sum())
    if total <= 0.0:
        return 0.0, IDENTITY, None
    centres = np.array([frame.position for frame in frames])
    centre = masses @ centres / total
    inertia = np.zeros((3, 3))
    for link, frame, offset in zip(model.links, frames, centres - centre):
        ixx, ixy, ixz, iyy, iyz, izz = link.inertia
        rotation = np.array(rotation_matrix(frame.orientation))
        local = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        # Rotate into the model frame, then move to the common centre (parallel-axis theorem).
        inertia += rotation @ local @ rotation.T + link.mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))
    from scipy.spatial.transform import Rotation  # only dynamic SDF models need it; it costs start-up 0.5 s
    moments, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] = -axes[:, 2]
    return total, Pose(tuple(centre), tuple(Rotation.from_matrix(axes).as_quat())), tuple(float(m) for m in moments)
