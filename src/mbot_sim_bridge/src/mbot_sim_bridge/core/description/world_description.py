"""What a world is, once read: physics, models, links and collision shapes in the world frame.

``sdf_world.parse_world`` fills these from a .world file; ``world_bodies`` builds them in PyBullet, the render
scene draws them, ``world_writer`` writes them back as SDF.
"""
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple

import numpy as np

from ..geometry import Pose, rotation_matrix
from .mesh import TriangleMesh
from .robot_model import RobotModel

SHAPE_KINDS = ("box", "cylinder", "sphere", "plane", "mesh")


@dataclass(frozen=True)
class PhysicsConfig:
    """``<physics>`` and gravity with SDF defaults (reference sheet §8)."""
    max_step_size: float = 0.001
    real_time_factor: float = 1.0
    real_time_update_rate: float = 1000.0
    gravity: Tuple[float, float, float] = (0.0, 0.0, -9.8)
    # <ode><constraints> (Engine): erp for joints; penetration is undone leaving a placed body at most
    # contact_max_correcting_vel (and the links' max_vel) of velocity; the surface layer is read, not applied.
    erp: float = 0.2
    contact_max_correcting_vel: float = 100.0
    contact_surface_layer: float = 0.001


@dataclass(frozen=True)
class Shape:
    """One collision geometry, posed in the world frame.

    ``size`` is the extent of the geometry along its own x, y, z axes: the box size, (2r, 2r, length) for a
    cylinder (axis along local z), 2r for a sphere, the visual ``<size>`` of a plane (its collision is
    infinite) and the scaled bounding box of a mesh (not necessarily centred on the pose).
    """
    model: str
    link: str  # nested models give scoped names, "inner::link"
    name: str
    kind: str  # one of SHAPE_KINDS
    pose: Pose
    size: Tuple[float, float, float]
    radius: float = 0.0
    length: float = 0.0
    normal: Tuple[float, float, float] = (0.0, 0.0, 1.0)
    mesh_path: Optional[str] = None
    mesh: Optional[TriangleMesh] = field(default=None, compare=False, repr=False)  # scaled, collision frame
    mu: float = 1.0
    mu2: float = 1.0
    rgba: Optional[Tuple[float, float, float, float]] = None  # the link's first visual material, for the window

    def world_points(self, segments: int = 32) -> np.ndarray:
        """(N, 3) world points whose convex hull encloses the shape; round parts are ``segments``-gons.

        Empty for a plane, which has no bounds.
        """
        angles = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
        circle = np.stack([np.cos(angles), np.sin(angles), np.zeros(segments)], axis=1)
        if self.kind == "sphere":  # rotation-invariant, so built straight in the world frame
            poles = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
            return np.asarray(self.pose.position) + self.radius * np.concatenate([circle, poles])
        if self.kind == "box":
            signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
            local = signs * np.asarray(self.size) / 2.0
        elif self.kind == "cylinder":
            rim = self.radius * circle
            local = np.concatenate([rim + [0, 0, self.length / 2.0], rim - [0, 0, self.length / 2.0]])
        elif self.kind == "mesh":
            local = self.mesh.vertices
        else:
            return np.empty((0, 3))
        return local @ np.asarray(rotation_matrix(self.pose.orientation)).T + np.asarray(self.pose.position)

    def bounds(self) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]:
        """World axis-aligned bounding box (minimum corner, maximum corner); infinite for a plane."""
        points = self.world_points()
        if len(points) == 0:
            return (-np.inf,) * 3, (np.inf,) * 3
        return tuple(float(v) for v in points.min(axis=0)), tuple(float(v) for v in points.max(axis=0))


@dataclass(frozen=True)
class LinkDescription:
    name: str
    pose: Pose  # world frame
    mass: float  # 0 in a static model
    inertia: Tuple[float, float, float, float, float, float]  # ixx ixy ixz iyy iyz izz, inertial frame
    inertial_pose: Pose  # link frame
    collisions: Tuple[Shape, ...]


@dataclass(frozen=True)
class ModelDescription:
    name: str
    static: bool
    pose: Pose  # world frame
    links: Tuple[LinkDescription, ...]
    # The world's <model> or <include> it was read from, so a saved world writes it back the same way.
    source: Optional[ET.Element] = field(default=None, compare=False, repr=False)

    @property
    def shapes(self) -> Tuple[Shape, ...]:
        return tuple(shape for link in self.links for shape in link.collisions)


@dataclass(frozen=True)
class ArticulatedModel:
    """A model with joints, sensors or plugins, simulated as a robot from the URDF it reads as (``sdf_model``)."""
    name: str
    static: bool
    pose: Pose  # world frame, as loaded
    robot: RobotModel
    root_in_model: Pose  # the robot's root link frame in the model frame
    source: Optional[ET.Element] = field(default=None, compare=False, repr=False)
    # Where the world's <state> (a saved world) puts its one-axis joints: set once it is spawned.
    joint_positions: Dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class WorldDescription:
    name: str
    path: str
    physics: PhysicsConfig
    models: Tuple[ModelDescription, ...]
    # World children other than models, physics, gravity and frames (lights, scene, gui...), kept for saving.
    others: Tuple[ET.Element, ...] = field(default=(), compare=False, repr=False)
    robots: Tuple[ArticulatedModel, ...] = ()
    # Why files it names are not simulated (a mesh or <include> not found or unreadable), each warned once.
    left_out: Tuple[str, ...] = field(default=(), compare=False)

    @property
    def plugins(self) -> Tuple[ET.Element, ...]:
        """The world's ``<plugin>`` elements (world plugins), in order."""
        return tuple(element for element in self.others if element.tag == "plugin")

    @property
    def shapes(self) -> Tuple[Shape, ...]:
        """Every collision of every model, in the world frame."""
        return tuple(shape for model in self.models for shape in model.shapes)
