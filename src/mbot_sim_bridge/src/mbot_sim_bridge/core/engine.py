"""PyBullet world: physics settings, spawned robots with named accessors, sim time, reset.

Each Engine owns its own BulletClient (never PyBullet's module-global client), so tests can run several
side by side. Sim time is kept as a whole number of physics steps, so it never drifts.
"""
import functools
import math
import os
import tempfile
from dataclasses import dataclass
from itertools import chain
from typing import Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from .errors import ModelError
from .geometry import (IDENTITY, Pose, compose, cross_products, inverse, quaternion_products, rotate,
                       rotation_matrices, rotation_matrix)
from .log import c_stdout_to, get_logger, info_once, warn_once
from .description.mesh import with_pybullet_readable_meshes
from .description.robot_model import RobotModel
from .description.world_description import PhysicsConfig
from .wheel_contact import WheelContacts, wheel
from .xml_values import MAX_POSITION
from .world_bodies import LoadedWorld

_logger = get_logger(__name__)

# Beyond these a body is lost to the simulation (Bullet's broadphase and solver overflow or lose all precision),
# so poses and velocities given from outside are refused past them; MAX_POSITION (m) bounds descriptions too.
MAX_SPEED = 1.0e4  # m/s and rad/s
# SDF's <surface><contact><ode><max_vel> when a link sets none (URDF <maxVel>): with the world's
# contact_max_correcting_vel, the most velocity Gazebo's ODE leaves a link with from undoing a penetration.
DEFAULT_SURFACE_MAX_VEL = 0.01  # m/s
# PyBullet's contact slop and error reduction, kept: its contacts leave this depth uncorrected (ODE's surface
# layer, 1 mm by default, is not applied: see _configure) and undo this fraction of the rest per step.
CONTACT_SLOP = 1.0e-5  # m
CONTACT_ERP = 0.08
# A placed body settles until it has gone this long without a contact deep enough for Bullet to undo it faster
# than the cap (at least PENETRATION_TOLERANCE beyond the slop); one still that deep after SETTLING_WARNING is said
# once (it stays watched).
SETTLED_AFTER = 0.01  # s of sim time
SETTLING_WARNING = 1.0  # s of sim time
PENETRATION_TOLERANCE = 1.0e-5  # m
# A friction coefficient far beyond any real one (rubber on asphalt is about 1); the wheel contact model's forces
# stay finite below it.
MAX_WHEEL_MU = 1.0e3
# PyBullet's own number of solver iterations (ODE's <iters> default is the same).
DEFAULT_SOLVER_ITERATIONS = 50
# Gazebo's default contact stiffness (SDF <kp>): a spring this stiff is a rigid contact.
RIGID_CONTACT_STIFFNESS = 1.0e12  # N/m
# A finger without mass (a massless link) is damped as one of a gram.
_MIN_SQUEEZING_MASS = 1.0e-3  # kg
# PyBullet's bodies hold at most this many links, the base included: with more, loadURDF builds a body whose
# every query fails ("GetBasePositionAndOrientation failed").
MAX_BODY_LINKS = 128


class StepFault(Exception):
    """Engine.step failed in the work it does for one model (its wheel contacts, the correction of its placement):
    the simulation contains it to ``model``. What Bullet's own step raises is not one model's and comes as is."""

    def __init__(self, model: str, part: str, error: Exception):
        super().__init__(f"{part}: {type(error).__name__}: {error}")
        self.model = model


class CachingBulletClient(BulletClient):
    """A BulletClient that binds each PyBullet function to its client once: BulletClient builds a new
    functools.partial on every attribute access, a few per cent of the bridge's loop."""

    def __getattr__(self, name):
        attribute = super().__getattr__(name)
        if name != "disconnect" and isinstance(attribute, functools.partial):
            setattr(self, name, attribute)  # found in the instance from now on, without __getattr__
        return attribute


@dataclass
class BodyState:
    pose: Tuple[Sequence[float], Sequence[float]]  # centre of mass position, orientation
    velocity: Tuple[Sequence[float], Sequence[float]]  # linear, angular
    # positions, velocities by joint index (one value each for one-axis joints, a quaternion for a spherical one)
    joints: List[Tuple[Sequence[float], Sequence[float]]]

    @property
    def finite(self) -> bool:
        joint_values = [part for joint in self.joints for part in joint]
        return all(math.isfinite(value) for part in (*self.pose, *self.velocity, *joint_values) for value in part)


@dataclass
class _InitialState:
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]
    joint_positions: Dict[int, Sequence[float]]  # a quaternion for a spherical joint (planar, floating)


def root_from_com(client: BulletClient, body: int) -> Pose:
    """PyBullet places a base at its centre of mass; this is the root link frame seen from there."""
    inertial = client.getDynamicsInfo(body, -1)
    return inverse(Pose(tuple(inertial[3]), tuple(inertial[4])))


def frame_pose(client: BulletClient, body: int, frame_from_com: Pose) -> Pose:
    position, orientation = client.getBasePositionAndOrientation(body)
    return compose(Pose(tuple(position), tuple(orientation)), frame_from_com)


def _point_velocity(com, linear, angular, point) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    """(v_com + ω × r, ω) for a point fixed to a body; r from the centre of mass to the point."""
    (vx, vy, vz), (wx, wy, wz) = linear, angular
    rx, ry, rz = (point[i] - com[i] for i in range(3))
    # Written out: numpy.cross costs more than a physics step on 3-vectors.
    return (vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx), (wx, wy, wz)


def frame_velocity(client: BulletClient, body: int, frame_position) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    """World-frame (linear velocity of a point fixed to the base, angular velocity)."""
    com, _ = client.getBasePositionAndOrientation(body)
    linear, angular = client.getBaseVelocity(body)
    return _point_velocity(com, linear, angular, frame_position)


def check_state(what: str, pose: Pose, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
    """ModelError naming the field when a requested pose or twist is not finite or beyond what Bullet can hold."""
    for name, values, limit in (("position", pose.position, MAX_POSITION), ("orientation", pose.orientation, 1.0),
                                ("linear velocity", linear, MAX_SPEED), ("angular velocity", angular, MAX_SPEED)):
        for axis, value in zip("xyzw", values):
            if not math.isfinite(value):
                raise ModelError(f"{what}: {name}.{axis} is {value}, not a finite number; nothing was changed")
            if abs(value) > limit * (1.0 + 1e-9):
                raise ModelError(f"{what}: {name}.{axis} = {value:g} is outside ±{limit:g}; nothing was changed")
    norm = math.hypot(*pose.orientation)
    if abs(norm - 1.0) > 1e-6:
        raise ModelError(f"{what}: orientation {tuple(pose.orientation)} is not a unit quaternion (norm {norm:g}); "
                         f"nothing was changed")


def check_model_name(what: str, name: str):
    """ModelError for a name Gazebo could not address: empty, with whitespace, Gazebo's scope separator "::"
    ("model::link" names a link) or "/"."""
    if not name or "::" in name or "/" in name or any(character.isspace() for character in name):
        raise ModelError(f"{what}: model name {name!r}: a model name must be non-empty, without whitespace, '::' "
                         f"(which separates a model's links) or '/'; nothing was spawned")


class RecordedLinkStates(NamedTuple):
    """A link frame at consecutive steps, one row each, in the world."""
    orientations: np.ndarray  # (N, 4) xyzw
    rotations: np.ndarray  # (N, 3, 3) the same as matrices
    linear: np.ndarray  # (N, 3) velocity of the frame's origin
    angular: np.ndarray  # (N, 3)


class SpawnedRobot:
    """A URDF robot in the engine, addressed by URDF link and joint names."""

    def __init__(self, client: BulletClient, name: str, model: RobotModel, body: int, namespace: str,
                 spawn_pose: Pose = IDENTITY):
        self.client = client
        self.name = name
        self.model = model
        self.body = body
        self.namespace = namespace
        self.spawn_pose = spawn_pose
        self.driven_joints: Tuple[str, ...] = ()
        self.loads = 1  # a new body (respawn) has every motor off, whatever a plugin set on the old one
        self.link_index: Dict[str, int] = {model.root: -1}
        # Bullet links of lumped links kept for their own surface: not links Gazebo has, so not in link_index.
        self.surface_link_index: Dict[str, int] = {}
        self.joint_index: Dict[str, int] = {}
        free_chain = set(model.free_chain_links())  # planar and floating joints' links, not Gazebo's
        for index in range(client.getNumJoints(body)):
            info = client.getJointInfo(body, index)
            link_name = info[12].decode()
            if link_name in model.separate_surfaces:
                self.surface_link_index[link_name] = index
            elif link_name not in free_chain:
                self.link_index[link_name] = index
            self.joint_index[info[1].decode()] = index
        self.root_from_com = root_from_com(client, body)
        self._frames_from_com: Dict[str, Pose] = {}  # a base-lumped link's frame seen from the centre of mass
        self.movable_joints = [joint.name for joint in model.movable_joints() if joint.name in self.joint_index]

    def root_pose(self) -> Pose:
        return frame_pose(self.client, self.body, self.root_from_com)

    def root_velocity(self):
        """World-frame (linear velocity of the root link frame's origin, angular velocity)."""
        return frame_velocity(self.client, self.body, self.root_pose().position)

    def link_world_pose(self, link_name: str) -> Pose:
        """World pose of any link's frame as Gazebo reports it, lumped ones included (RobotModel.reported_frame)."""
        body_link, offset = self.model.reported_frame(link_name)
        frame = self.body_link_pose(body_link)
        return compose(frame, offset) if offset != IDENTITY else frame

    def body_link_pose(self, body_link: str) -> Pose:
        """World pose of a simulated link's URDF frame (its joint's frame), which its collisions are given in."""
        index = self.link_index[body_link]
        if index == -1:
            return self.root_pose()
        state = self.client.getLinkState(self.body, index, computeForwardKinematics=True)
        return Pose(tuple(state[4]), tuple(state[5]))

    def bullet_links(self, link_name: str) -> List[int]:
        """The Bullet links holding the collisions of a simulated link: its own and its separate surfaces'."""
        return [self.link_index[link_name]] + [index for name, index in self.surface_link_index.items()
                                               if self.model.lumped_into[name][0] == link_name]

    def joint_state(self, joint_names: Sequence[str]) -> List[Tuple[float, float, float]]:
        """(position, velocity, applied effort) per named joint."""
        rows = self.joint_rows([self.joint_index[name] for name in joint_names])
        return [(row[0], row[1], row[3]) for row in rows]

    def joint_rows(self, indices: Sequence[int]):
        """PyBullet's getJointStates rows (position, velocity, reaction wrench, applied effort) of joints by
        ``joint_index``: joint_state without its name lookups and copies, for readers after every step. PyBullet
        answers None for no joints."""
        return self.client.getJointStates(self.body, indices) or ()

    def link_world_velocity(self, link_name: str):
        """World-frame (linear velocity of the origin of the frame link_world_pose gives; angular velocity)."""
        index = self.link_index[self.model.reported_frame(link_name)[0]]
        point = self.link_world_pose(link_name).position
        if index == -1:
            return frame_velocity(self.client, self.body, point)
        state = self.client.getLinkState(self.body, index, computeLinkVelocity=True)
        return _point_velocity(state[0], state[6], state[7], point)

    def link_state_recorder(self, link_name: str, rows: list) -> Callable[[], None]:
        """A call that appends the Bullet state of ``link_name``'s body link to ``rows``, for ``Engine.step`` to
        make after every step (about 3.5 us); ``recorded_link_states`` turns the rows into world values."""
        index = self.link_index[self.model.lumped_into[link_name][0]]
        body, append = self.body, rows.append
        if index == -1:
            pose, velocity = self.client.getBasePositionAndOrientation, self.client.getBaseVelocity
            return lambda: append(pose(body) + velocity(body))
        state = self.client.getLinkState
        return lambda: append(state(body, index, 1, 1))

    def recorded_link_states(self, link_name: str, rows: Sequence[tuple]) -> RecordedLinkStates:
        """From ``link_state_recorder``'s rows, the frame of ``link_name`` at each step, as ``link_world_pose``
        and ``link_world_velocity`` would have given it then."""
        body_link, offset = self.model.reported_frame(link_name)
        on_base = self.link_index[body_link] == -1
        width = 13 if on_base else 27
        # np.fromiter over the nested tuples costs half of joining each row into one tuple for np.array.
        state = np.fromiter(chain.from_iterable(chain.from_iterable(rows)), float, len(rows) * width)
        state = state.reshape(len(rows), width)
        # The offset of the frame is taken from a reference frame: the base's centre of mass, or the link's frame.
        if on_base:
            # The base's rows: its centre of mass's position, orientation, linear and angular velocity.
            reference_orientations, com_linear, angular = state[:, 3:7], state[:, 7:10], state[:, 10:13]
            com_to_reference = None  # the reference is the centre of mass
            if link_name not in self._frames_from_com:
                self._frames_from_com[link_name] = compose(self.root_from_com, offset)
            offset = self._frames_from_com[link_name]
        else:
            # getLinkState: 0 centre of mass, 4 and 5 the link frame, 6 and 7 the centre of mass's velocity.
            reference_orientations, com_linear, angular = state[:, 17:21], state[:, 21:24], state[:, 24:27]
            com_to_reference = state[:, 14:17] - state[:, :3]
        reference_rotations = rotation_matrices(reference_orientations)
        com_to_frame = reference_rotations @ offset.position
        if com_to_reference is not None:
            com_to_frame += com_to_reference
        linear = com_linear + cross_products(angular, com_to_frame)
        if offset.orientation == IDENTITY.orientation:
            return RecordedLinkStates(reference_orientations, reference_rotations, linear, angular)
        return RecordedLinkStates(quaternion_products(reference_orientations, offset.orientation),
                                  reference_rotations @ np.array(rotation_matrix(offset.orientation)), linear, angular)

    def set_root_velocity(self, linear: Sequence[float], angular: Sequence[float]):
        """The base's world-frame velocity (of its centre of mass), as Gazebo's Model::SetLinearVel and
        SetAngularVel set the canonical link's."""
        self.client.resetBaseVelocity(self.body, linear, angular)

    def set_joint_velocity(self, joint_name: str, velocity: float, max_force: float):
        """A velocity motor, as Gazebo's ODE joint 'vel' + 'fmax' pair."""
        self.client.setJointMotorControl2(self.body, self.joint_index[joint_name], pybullet.VELOCITY_CONTROL,
                                          targetVelocity=velocity, force=max_force)

    def set_joint_position(self, joint_name: str, position: float, max_force: float, velocity: float = 0.0):
        """A position servo reaching ``position`` with at most ``max_force`` (N·m or N); ``velocity``, the
        target's own speed, keeps a servo following a moving target from lagging behind it."""
        self.client.setJointMotorControl2(self.body, self.joint_index[joint_name], pybullet.POSITION_CONTROL,
                                          targetPosition=position, targetVelocity=velocity, force=max_force)

    def set_joint_effort(self, joint_name: str, effort: float):
        """A torque (or force) for the next physics step only (PyBullet's TORQUE_CONTROL); it acts only once
        the joint's velocity motor is off (``release_joint``). Controllers send it again every step."""
        self.client.setJointMotorControl2(self.body, self.joint_index[joint_name], pybullet.TORQUE_CONTROL,
                                          force=effort)

    def set_joint_positions(self, positions: Dict[str, float]):
        """Joints put at positions, at rest (set_model_configuration), outside the physics."""
        for joint_name, position in positions.items():
            self.client.resetJointState(self.body, self.joint_index[joint_name], position, 0.0)

    def release_joint(self, joint_name: str):
        """No motor: PyBullet holds every joint with a velocity motor unless told otherwise."""
        self.set_joint_velocity(joint_name, 0.0, 0.0)

    def release_spherical_joint(self, joint_name: str):
        """No motor on a spherical joint (a ball joint, a planar or floating joint's): PyBullet's holds it."""
        self.client.setJointMotorControlMultiDof(self.body, self.joint_index[joint_name], pybullet.POSITION_CONTROL,
                                                 targetPosition=[0.0, 0.0, 0.0, 1.0], targetVelocity=[0.0, 0.0, 0.0],
                                                 positionGain=0.0, velocityGain=0.0, force=[0.0, 0.0, 0.0])


class Engine:
    def __init__(self, physics: PhysicsConfig = PhysicsConfig(), connection_mode: int = pybullet.DIRECT):
        self.client = CachingBulletClient(connection_mode=connection_mode)
        self.physics = physics
        self.solver_iterations = DEFAULT_SOLVER_ITERATIONS  # ODE's <iters>, set_physics_properties' sor_pgs_iters
        self._configure()
        self.steps = 0
        # Sim time at step 0 of the current step size: set_physics_properties changes the step size mid-run.
        self.time_offset = 0.0
        # How many times the world was built again (restart): PyBullet then numbers bodies and constraints anew.
        self.rebuilds = 0
        self.robots: Dict[str, SpawnedRobot] = {}
        self.world_bodies: Dict[str, int] = {}
        self.dynamic_world_bodies: Dict[str, int] = {}  # those with mass, which the physics moves
        # PyBullet body -> link index -> Gazebo's "model::link::collision" of the collision it holds.
        self.collision_names: Dict[int, Dict[int, str]] = {}
        self._initial: Dict[int, _InitialState] = {}
        # Per body, the model frame seen from the centre of mass where PyBullet places a base.
        self._root_from_com: Dict[int, Pose] = {}
        # Bodies placed where they may penetrate others (spawn, set_model_state, reset): body -> [steps settling,
        # steps since its last deep contact]; see _bound_correction.
        self._settling: Dict[int, List[int]] = {}
        self._wheels: Dict[int, WheelContacts] = {}  # per body, the friction of its wheels (wheel_contact)
        self._before_step: List[Callable[[], None]] = []
        # set_joint_properties' damping: body -> joint index -> N·m·s/rad; set_link_properties' gravity_mode
        # false: body -> link indices.
        self._joint_damping: Dict[int, Dict[int, float]] = {}
        self._weightless: Dict[int, set] = {}

    def _configure(self):
        self.client.setTimeStep(self.physics.max_step_size)
        self.client.setGravity(*self.physics.gravity)
        # Same inputs, same contacts: keeps two runs (and two tests) identical.
        # Friction along two tangent directions, as ODE's pyramid model that Gazebo uses: Bullet's default cone
        # friction made four-wheel skid-steer bases turn in place by fits and starts (yaw rate 0.08 to 0.8 rad/s
        # for a steady 0.8 command).
        self.client.setPhysicsEngineParameter(deterministicOverlappingPairs=1, enableConeFriction=0)
        # The world's <ode><constraints> erp is ODE's error reduction for joints, Bullet's erp (the SDF default is
        # PyBullet's). Contacts keep PyBullet's contactERP (0.08), as ODE's take theirs from the surfaces' kp and
        # kd, and PyBullet's slop: ODE's 1 mm surface layer as the slop sank every robot and gripper finger 1 mm
        # into what it touches and moved the skid-steer turn figures by 1 %.
        self.client.setPhysicsEngineParameter(contactSlop=CONTACT_SLOP, contactERP=CONTACT_ERP, erp=self.physics.erp,
                                              numSolverIterations=self.solver_iterations)

    def restart(self):
        """An empty world at sim time 0, as a fresh Engine; the caller builds the models again.

        reset_simulation goes through here rather than restoring poses: Bullet keeps contact caches and
        solver warm-start state that a restore does not reset, so only a rebuild repeats a run bit for bit.
        """
        self.client.resetSimulation()
        self._configure()
        self.steps = 0
        self.time_offset = 0.0
        self.rebuilds += 1
        self.robots.clear()
        self.world_bodies.clear()
        self.dynamic_world_bodies.clear()
        self.collision_names.clear()
        self._initial.clear()
        self._root_from_com.clear()
        self._settling.clear()
        self._wheels.clear()
        self._joint_damping.clear()
        self._weightless.clear()
        self._before_step = []

    @property
    def sim_time(self) -> float:
        return self.time_offset + self.steps * self.physics.max_step_size

    def set_physics(self, physics: PhysicsConfig, solver_iterations: int):
        """New physics settings between two steps (set_physics_properties); sim time goes on from where it is."""
        self.time_offset = self.sim_time - self.steps * physics.max_step_size
        self.physics, self.solver_iterations = physics, solver_iterations
        self._configure()
        for robot in self.robots.values():  # the wheel contact model is made for one step size
            self.set_surfaces(robot, robot.driven_joints)

    def step(self, count: int = 1, after_each: Sequence[Callable[[], None]] = ()):
        """``count`` physics steps; the wheels' friction (wheel_contact) and the forces of set joint and link
        properties are applied before every one, and each of
        ``after_each`` (recorders of per-step state, then the plugins that act on every step) is called after
        every one, with ``sim_time`` already that step's. ``steps`` counts each step as it is taken, so after a
        failure it holds the steps done; StepFault names the model whose part of the step raised."""
        step = self.client.stepSimulation  # one attribute lookup: BulletClient builds a partial on each
        before = self._before_step
        while self._settling and count > 0:
            for call in before:
                call()
            step()
            self.steps += 1
            count -= 1
            self._bound_correction()
            for call in after_each:
                call()
        if after_each or before:
            for _ in range(count):
                for call in before:
                    call()
                step()
                self.steps += 1
                for call in after_each:
                    call()
        else:
            for _ in range(count):
                step()
                self.steps += 1

    def _apply_wheels(self):
        for body, wheels in self._wheels.items():
            try:
                wheels.apply()
            except Exception as error:  # one robot's wheel arithmetic; its model is contained by the caller
                raise StepFault(self._name_of(body), "wheel contacts", error) from error

    def add_world(self, world: LoadedWorld):
        """Register the bodies a world loader built, so reset and model queries know them."""
        for name, body in world.bodies.items():
            self.world_bodies[name] = body
            if self.client.getDynamicsInfo(body, -1)[0] > 0.0:
                self.dynamic_world_bodies[name] = body
            shapes = [shape for shape in world.shapes if shape.model == name]
            # One static collision is the body's base; otherwise each collision is a child link, in order.
            links = [-1] if self.client.getNumJoints(body) == 0 else range(len(shapes))
            self.collision_names[body] = {link: f"{name}::{shape.link}::{shape.name}"
                                          for link, shape in zip(links, shapes)}
            self._root_from_com[body] = inverse(world.inertial_frames[name])
            self._remember_initial_state(body)
            self._settle(body)

    def model_names(self) -> List[str]:
        return list(self.world_bodies) + list(self.robots)

    def spawn_robot(self, model: RobotModel, name: str, pose: Pose = IDENTITY, namespace: str = "/",
                    driven_joints: Optional[Sequence[str]] = ()) -> SpawnedRobot:
        """Load ``model`` as ``name``; ``driven_joints`` (those a plugin drives) decide which links are casters.

        None leaves the surfaces to a later ``set_surfaces``, once the plugins have said what they drive.
        """
        if name in self.robots or name in self.world_bodies:
            raise ModelError(f"model '{name}' already exists")
        check_model_name("SpawnModel", name)
        check_state(f"SpawnModel: model '{name}'", pose)
        body_links = len({holder for holder, _ in model.lumped_into.values()})
        if body_links > MAX_BODY_LINKS:
            raise ModelError(f"SpawnModel: model '{name}': {body_links - 1} movable joints; a PyBullet body holds at "
                             f"most {MAX_BODY_LINKS - 1} ({MAX_BODY_LINKS} links with the base); nothing was spawned")
        robot = SpawnedRobot(self.client, name, model, self._load_urdf(model, pose), namespace, pose)
        self._place(robot, driven_joints)
        return robot

    def respawn(self, robot: SpawnedRobot):
        """Load ``robot`` again at its spawn pose after ``restart``; the same object gets the new body."""
        robot.body = self._load_urdf(robot.model, robot.spawn_pose)
        robot.loads += 1
        self._place(robot, robot.driven_joints)

    def _place(self, robot: SpawnedRobot, driven_joints: Optional[Sequence[str]]):
        if driven_joints is not None:
            self.set_surfaces(robot, driven_joints)
        for joint_name in robot.movable_joints + robot.model.free_chain_joints():
            robot.release_joint(joint_name)
        for joint in robot.model.joints.values():
            if joint.spherical:
                robot.release_spherical_joint(joint.name)
        self.robots[robot.name] = robot
        # A link holding several collisions is named by its first: Bullet reports contacts per link. A separate
        # surface's Bullet link is named by its own, which Gazebo holds in the link it is lumped into.
        indices = {**robot.link_index, **robot.surface_link_index}
        self.collision_names[robot.body] = {
            indices[link]: f"{robot.name}::{robot.model.lumped_into[link][0]}::{names[0]}"
            for link, names in robot.model.bullet_collision_names().items() if names and link in indices}
        self._root_from_com[robot.body] = robot.root_from_com
        self._remember_initial_state(robot.body)
        self._settle(robot.body, anchored=robot.model.anchored)

    def remove(self, name: str):
        if name in self.robots:
            body = self.robots.pop(name).body
        elif name in self.world_bodies:
            body = self.world_bodies.pop(name)
            self.dynamic_world_bodies.pop(name, None)
        else:
            raise ModelError(f"model '{name}' does not exist")
        self._initial.pop(body, None)
        self._root_from_com.pop(body, None)
        self._settling.pop(body, None)
        self.collision_names.pop(body, None)
        self._set_wheels(body, None)
        self._joint_damping.pop(body, None)
        self._weightless.pop(body, None)
        self._refresh_before_step()
        self.client.removeBody(body)

    def body_of(self, name: str) -> int:
        if name in self.robots:
            return self.robots[name].body
        if name in self.world_bodies:
            return self.world_bodies[name]
        raise ModelError(f"model '{name}' does not exist")

    def model_pose(self, name: str) -> Pose:
        """World pose of a model's frame (a robot's root link, a world model's <model> frame)."""
        body = self.body_of(name)
        return frame_pose(self.client, body, self._root_from_com[body])

    def model_velocity(self, name: str):
        """World-frame (linear velocity of the model frame's origin, angular velocity)."""
        return frame_velocity(self.client, self.body_of(name), self.model_pose(name).position)

    def apply_link_wrench(self, body: int, index: int, force, torque):
        """A world-frame force at the link's centre of mass and a torque, for the next physics step only (as
        Gazebo's Link::SetForce and SetTorque)."""
        centre = (self.client.getBasePositionAndOrientation(body)[0] if index == -1
                  else self.client.getLinkState(body, index)[0])
        self.client.applyExternalForce(body, index, force, centre, pybullet.WORLD_FRAME)
        self.client.applyExternalTorque(body, index, torque, pybullet.WORLD_FRAME)

    def set_model_state(self, name: str, pose: Pose, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
        """Move a model's frame to ``pose`` and give every link the same world velocity (as Gazebo does)."""
        body = self.body_of(name)
        check_state(f"SetModelState: model '{name}'", pose, linear, angular)
        com = compose(pose, inverse(self._root_from_com[body]))
        self.client.resetBasePositionAndOrientation(body, com.position, com.orientation)
        self.client.resetBaseVelocity(body, linear, angular)
        self._settle(body)

    def move_model(self, name: str, pose: Pose, point, linear, angular, stop_joints: bool):
        """Move a model's frame to ``pose``, as one rigid body turning at ``angular`` whose ``point`` (world, after
        the move) has velocity ``linear``; ``stop_joints``: its joints' velocities become 0 (set_link_state)."""
        body = self.body_of(name)
        com = compose(pose, inverse(self._root_from_com[body]))
        self.client.resetBasePositionAndOrientation(body, com.position, com.orientation)
        com_linear = np.add(linear, np.cross(angular, np.subtract(com.position, point)))
        self.client.resetBaseVelocity(body, com_linear.tolist(), list(angular))
        if stop_joints:
            for index, (position, *_) in enumerate(self.client.getJointStates(
                    body, range(self.client.getNumJoints(body))) or ()):
                self.client.resetJointState(body, index, position, 0.0)
        self._settle(body)

    def set_joint_positions(self, robot: SpawnedRobot, positions: Dict[str, float]):
        """Joints of a robot put at positions, at rest (set_model_configuration)."""
        robot.set_joint_positions(positions)
        self._settle(robot.body, anchored=robot.model.anchored)

    def reset_world(self):
        """Every model back to its spawn pose and joint positions, at rest (Gazebo's reset_world)."""
        for body in self._initial:
            self._restore_initial_state(body)
            self._settle(body)

    def _settle(self, body: int, anchored: bool = False):
        """Watch a body just placed (see _bound_correction); bodies that cannot move need no watching."""
        if not anchored and self.client.getDynamicsInfo(body, -1)[0] > 0.0:
            self._settling[body] = [0, 0]

    def _bound_correction(self):
        """Penetration undone as Gazebo's ODE undoes it: the contacts move a body out at their error reduction
        rate, but leave it with a separating velocity of at most min(link max_vel, contact_max_correcting_vel)
        (ODE solves the correction apart from the velocity). Bullet's multibody contacts turn the whole correction
        into velocity (its split impulse is for rigid bodies only), which threw a robot spawned 13 cm into the
        ground 4.6 m up. So after each step, where a contact of a placed body is deep enough for Bullet to undo it
        faster than the cap (resting contacts are not), the velocities of the bodies in it are scaled so that they
        move apart there at no more than the cap (the whole relative speed, not only its normal part: through
        friction and rotation the correction also pushes sideways, which carried a box wedged between two walls
        off at 1 m/s).

        Bodies are watched from their placement until they have been clear of deep contacts for SETTLED_AFTER:
        contacts that arise in motion keep Bullet's behaviour (and its cost), as before. A wedged body stays
        watched, as ODE caps its contacts for ever."""
        client, physics = self.client, self.physics
        cap = min(physics.contact_max_correcting_vel, DEFAULT_SURFACE_MAX_VEL)
        deep = CONTACT_SLOP + max(PENETRATION_TOLERANCE, cap * physics.max_step_size / CONTACT_ERP)
        settled_after = max(1, round(SETTLED_AFTER / physics.max_step_size))
        scales: Dict[int, float] = {}
        for body, counts in list(self._settling.items()):
            counts[0] += 1
            counts[1] += 1
            try:
                for point in client.getContactPoints(bodyA=body):
                    if -point[8] <= deep:
                        continue
                    counts[1] = 0
                    body_a, body_b, link_a, link_b, on_a, on_b, normal_on_b = point[1:8]
                    velocity_a = self._point_velocity(body_a, link_a, on_a)
                    velocity_b = self._point_velocity(body_b, link_b, on_b)
                    speed = math.dist(velocity_a, velocity_b)
                    if speed > cap:
                        for moved in (body_a, body_b):
                            scales[moved] = min(scales.get(moved, 1.0), cap / speed)
            except Exception as error:  # one placed body's arithmetic; its model is contained by the caller
                raise StepFault(self._name_of(body), "placement correction", error) from error
            if counts[1] >= settled_after:
                del self._settling[body]
            elif counts[0] == round(SETTLING_WARNING / physics.max_step_size):
                warn_once(_logger, f"model '{self._name_of(body)}' is still inside another model "
                                   f"{SETTLING_WARNING:g} s after it was placed (wedged?); it is pushed out at "
                                   f"{cap:g} m/s at most")
        if scales:
            self._scale_velocities(scales)

    def _scale_velocities(self, scales: Dict[int, float]):
        """Each body's base twist and joint velocities times its scale: a wheel pushed out of a wall spins with the
        correction too, and would drive the robot away."""
        client = self.client
        joints = {robot.body: [robot.joint_index[name] for name in robot.movable_joints]
                  for robot in self.robots.values()}
        for body, scale in scales.items():
            linear, angular = client.getBaseVelocity(body)
            client.resetBaseVelocity(body, [scale * value for value in linear], [scale * value for value in angular])
            indices = joints.get(body)
            if indices:
                for index, (position, velocity, *_) in zip(indices, client.getJointStates(body, indices)):
                    client.resetJointState(body, index, position, scale * velocity)

    def _point_velocity(self, body: int, link: int, point) -> Tuple[float, ...]:
        if link == -1:
            return frame_velocity(self.client, body, point)[0]
        state = self.client.getLinkState(body, link, computeLinkVelocity=1)
        return _point_velocity(state[0], state[6], state[7], point)[0]

    def _name_of(self, body: int) -> str:
        return next(name for name in self.model_names() if self.body_of(name) == body)

    def models_not_finite(self) -> List[str]:
        """The robots and moving world models whose base pose the last steps made NaN or infinite. Run after every
        batch of steps, so kept to one state query and one sum per body (a NaN or inf anywhere makes the sum so)."""
        state, finite = self.client.getBasePositionAndOrientation, math.isfinite
        bodies = chain(((name, robot.body) for name, robot in self.robots.items()), self.dynamic_world_bodies.items())
        broken = []
        for name, body in bodies:
            position, orientation = state(body)
            if not finite(sum(position) + sum(orientation)):
                broken.append(name)
        return broken

    def body_states(self, names: Sequence[str]) -> Dict[str, "BodyState"]:
        """These models' base pose and velocity and joint states, to carry them across a ``restart``."""
        client, states = self.client, {}
        for name in names:
            body = self.body_of(name)
            count = client.getNumJoints(body)
            joints = client.getJointStatesMultiDof(body, range(count)) if count else []
            states[name] = BodyState(client.getBasePositionAndOrientation(body), client.getBaseVelocity(body),
                                     [(position, velocity) for position, velocity, *_ in joints])
        return states

    def restore_body_state(self, name: str, state: "BodyState"):
        body = self.body_of(name)
        self.client.resetBasePositionAndOrientation(body, *state.pose)
        self.client.resetBaseVelocity(body, *state.velocity)
        # Fixed joints have no state, and PyBullet refuses an empty one. One joint per call: PyBullet 3.2.7's
        # resetJointStatesMultiDof (all joints at once) crashed the process on a robot's saved states.
        for index, (positions, velocities) in enumerate(state.joints):
            if positions:
                self.client.resetJointStateMultiDof(body, index, list(positions), list(velocities))

    def _restore_initial_state(self, body: int):
        initial = self._initial[body]
        self.client.resetBasePositionAndOrientation(body, initial.position, initial.orientation)
        self.client.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0))
        for index, position in initial.joint_positions.items():  # one per call, as in restore_body_state
            self.client.resetJointStateMultiDof(body, index, list(position), [0.0] * (3 if len(position) == 4 else
                                                                                       len(position)))

    def close(self):
        if self.client is not None:
            self.client.disconnect()
            self.client = None

    def _load_urdf(self, model: RobotModel, pose: Pose) -> int:
        # PyBullet reads URDF only from a file; a private temp folder keeps the source tree untouched and holds
        # the binary copies of STL meshes PyBullet cannot read.
        with tempfile.TemporaryDirectory(prefix="mbot_sim_bridge_") as folder:
            return self._load_urdf_in(model, pose, folder)

    def _load_urdf_in(self, model: RobotModel, pose: Pose, folder: str) -> int:
        path = os.path.join(folder, "model.urdf")
        with open(path, "w") as urdf_file:
            urdf_file.write(with_pybullet_readable_meshes(model.pybullet_urdf, folder))
        try:
            # Fixed joints come lumped (RobotModel), so PyBullet's URDF_MERGE_FIXED_LINKS is not asked for.
            flags = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
            # PyBullet's URDF importer prints what it does; keep it out of the node's output.
            with open(os.devnull, "w") as devnull, c_stdout_to(devnull):
                body = self.client.loadURDF(path, flags=flags, useFixedBase=model.anchored)
        except pybullet.error as error:
            raise ModelError(f"PyBullet could not load model '{model.name}': {error}") from None
        com = compose(pose, inverse(root_from_com(self.client, body)))
        self.client.resetBasePositionAndOrientation(body, com.position, com.orientation)
        return body

    def set_surfaces(self, robot: SpawnedRobot, driven_joints: Sequence[str]):
        """Friction of every Bullet link; ball casters (see RobotModel.caster_links) are those on joints not driven."""
        robot.driven_joints = tuple(driven_joints)
        casters = set(robot.model.caster_links(driven_joints))
        if casters:  # said once: set_physics_properties sets the surfaces again
            info_once(_logger, f"{robot.name}: ball-caster contact (frictionless) for {', '.join(sorted(casters))}")
        source = f"model '{robot.name}'"
        # The wheels that carry fdir1 get the wheel contact model; Gazebo's ODE too turns friction with them only.
        modelled = {link_name: wheel_axle for link_name, wheel_axle in robot.model.wheels.items()
                    if robot.model.fdir1(link_name, source) is not None and link_name in robot.link_index}
        for link_name, index in {**robot.link_index, **robot.surface_link_index}.items():
            self._set_surface(robot, link_name, index, caster=link_name in casters, modelled=link_name in modelled)
        mass = sum(self.client.getDynamicsInfo(robot.body, index)[0] for index in range(-1, robot.client.getNumJoints(
            robot.body)))
        contacts = []
        driven_links = {robot.model.joints[joint].child for joint in driven_joints if joint in robot.model.joints}
        for link_name, (centre, axle) in modelled.items():
            index = robot.link_index[link_name]
            mu1, mu2 = robot.model.links[link_name].surface(source)
            if max(mu1, mu2) > MAX_WHEEL_MU:
                warn_once(_logger, f"{robot.name}: link '{link_name}' mu1 {mu1:g} / mu2 {mu2:g}: a wheel's friction "
                                   f"is taken as at most {MAX_WHEEL_MU:g} (beyond, its force would overflow)")
                mu1, mu2 = min(mu1, MAX_WHEEL_MU), min(mu2, MAX_WHEEL_MU)
            share = mass / len(robot.model.wheels)
            along = share if link_name in driven_links else 1.0 / (
                1.0 / share + robot.model.links[link_name].collision_radii[0] ** 2 / self._axle_inertia(
                    robot.body, index, axle))
            contacts.append(wheel(index, centre, axle, robot.model.fdir1(link_name, source), mu1, mu2,
                                  (along, share), self.physics.max_step_size))
        for link_name, link in robot.model.links.items():
            if link.gazebo_tag("fdir1") is not None and link_name not in robot.model.wheels:
                warn_once(_logger, f"{robot.name}: link '{link_name}' <fdir1> acts on wheels only (cylinders about "
                                   "their joint's axis); ignored")
        self._set_wheels(robot.body, WheelContacts(self.client, robot.body, contacts) if contacts else None)

    def _axle_inertia(self, body: int, index: int, axle: Sequence[float]) -> float:
        """A link's moment of inertia about an axis through its centre of mass along ``axle`` (its frame)."""
        info = self.client.getDynamicsInfo(body, index)
        inertial_axle = rotate(inverse(Pose((0.0, 0.0, 0.0), tuple(info[4]))).orientation, axle)
        return max(sum(moment * value * value for moment, value in zip(info[2], inertial_axle)), 1e-12)

    def _set_wheels(self, body: int, contacts: Optional[WheelContacts]):
        if contacts is None:
            self._wheels.pop(body, None)
        else:
            self._wheels[body] = contacts
        self._refresh_before_step()

    def _refresh_before_step(self):
        self._before_step = [self._apply_wheels] if self._wheels else []
        if self._joint_damping:
            self._before_step.append(self._damp_joints)
        if self._weightless:
            self._before_step.append(self._cancel_weights)

    # -- link and joint properties set from outside (entity_properties) ------------------------------------------
    def set_joint_damping(self, body: int, index: int, damping: float):
        """A torque of -damping times the joint's rate before every step (0: none)."""
        joints = self._joint_damping.setdefault(body, {})
        joints[index] = damping
        if not damping:
            del joints[index]
        if not joints:
            del self._joint_damping[body]
        self._refresh_before_step()

    def joint_damping(self, body: int, index: int) -> float:
        return self._joint_damping.get(body, {}).get(index, 0.0)

    def set_weightless(self, body: int, index: int, weightless: bool):
        """Whether a force cancels the link's weight before every step (Gazebo's gravity_mode false)."""
        links = self._weightless.setdefault(body, set())
        (links.add if weightless else links.discard)(index)
        if not links:
            del self._weightless[body]
        self._refresh_before_step()

    def weightless(self, body: int, index: int) -> bool:
        return index in self._weightless.get(body, ())

    def _damp_joints(self):
        client = self.client
        for body, joints in self._joint_damping.items():
            for index, (_, rate, *_) in zip(joints, client.getJointStates(body, list(joints))):
                client.setJointMotorControl2(body, index, pybullet.TORQUE_CONTROL, force=-joints[index] * rate)

    def _cancel_weights(self):
        client, gravity = self.client, self.physics.gravity
        for body, links in self._weightless.items():
            for index in links:
                mass = client.getDynamicsInfo(body, index)[0]
                centre = (client.getBasePositionAndOrientation(body)[0] if index == -1
                          else client.getLinkState(body, index)[0])
                client.applyExternalForce(body, index, [-mass * g for g in gravity], centre, pybullet.WORLD_FRAME)

    def _set_surface(self, robot: SpawnedRobot, link_name: str, index: int, caster: bool, modelled: bool):
        mu1, mu2 = robot.model.bullet_surface(link_name, f"model '{robot.name}'")
        if mu1 != mu2 and not modelled:
            warn_once(_logger, f"{robot.name}: link '{link_name}' has mu1 {mu1:g} and mu2 {mu2:g}; Bullet's friction "
                               "is isotropic, the smaller is used")
        # A wheel's friction is the wheel contact model's (wheel_contact), not Bullet's.
        self.client.changeDynamics(robot.body, index, lateralFriction=0.0 if caster or modelled else min(mu1, mu2),
                                   spinningFriction=0.0, rollingFriction=0.0, restitution=0.0)
        stiffness = self._squeezing_contact(robot, link_name)
        if stiffness is not None:
            self.client.changeDynamics(robot.body, index, contactStiffness=stiffness[0], contactDamping=stiffness[1])

    def _squeezing_contact(self, robot: SpawnedRobot, link_name: str) -> Optional[Tuple[float, float]]:
        """(contact stiffness N/m, damping N·s/m) for a link on a prismatic joint (a gripper finger), else None.

        ODE lets a contact rest within the world's contact_surface_layer uncorrected, so a finger pressed on a
        box stands still in Gazebo. Bullet's rigid contacts push it out by the whole depth every step and it
        reads effort·step/mass of velocity while it does not move (0.06 m/s at 30 N), so a gripper action never
        stalls. As a spring (ODE's kp/kd, which Bullet combines per pair as ODE does) that holds the joint's
        effort limit within the surface layer, critically damped for the link's mass, it rests (0 m/s)."""
        joint = next((joint for joint in robot.model.joints.values() if joint.child == link_name), None)
        layer = self.physics.contact_surface_layer
        if joint is None or joint.type != "prismatic" or joint.effort <= 0.0 or layer <= 0.0:
            return None
        stiffness = min(joint.effort / layer, RIGID_CONTACT_STIFFNESS)
        mass = max(robot.model.links[link_name].mass, _MIN_SQUEEZING_MASS)
        return stiffness, 2.0 * math.sqrt(stiffness * mass)

    def _remember_initial_state(self, body: int):
        position, orientation = self.client.getBasePositionAndOrientation(body)
        count = self.client.getNumJoints(body)
        states = self.client.getJointStatesMultiDof(body, range(count)) if count else []
        joints = {index: position for index, (position, *_) in enumerate(states) if position}  # not fixed ones
        self._initial[body] = _InitialState(tuple(position), tuple(orientation), joints)
