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
from .geometry import (IDENTITY, Pose, compose, cross_products, inverse, quaternion_products, rotation_matrices,
                       rotation_matrix)
from .log import c_stdout_to, get_logger, warn_once
from .robot_model import RobotModel
from .world_description import PhysicsConfig
from .world_bodies import LoadedWorld
from .xml_values import check_range, parse_float

_logger = get_logger(__name__)

# Beyond these a body is lost to the simulation (Bullet's broadphase and solver overflow or lose all precision),
# so poses and velocities given from outside are refused past them.
MAX_POSITION = 1.0e5  # m
MAX_SPEED = 1.0e4  # m/s and rad/s
# Gazebo's default friction coefficient for a surface that sets none (ODE mu = mu2 = 1).
DEFAULT_MU = 1.0
# PyBullet's bodies hold at most this many links, the base included: with more, loadURDF builds a body whose
# every query fails ("GetBasePositionAndOrientation failed").
MAX_BODY_LINKS = 128


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
    joints: List[Tuple[float, float]]  # position, velocity by joint index

    @property
    def finite(self) -> bool:
        return all(math.isfinite(value) for part in (*self.pose, *self.velocity, *self.joints) for value in part)


@dataclass
class _InitialState:
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]
    joint_positions: Dict[int, float]


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


def _friction(text: str, model: str, link: str) -> float:
    try:
        value = parse_float(text)
        check_range(value, minimum=0.0)
    except ValueError as error:
        raise ModelError(f"model '{model}': <gazebo reference='{link}'> friction '{text}': {error}") from None
    return value


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
        self.joint_index: Dict[str, int] = {}
        for index in range(client.getNumJoints(body)):
            info = client.getJointInfo(body, index)
            self.link_index[info[12].decode()] = index
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
        """World pose of any URDF link's frame, lumped ones included."""
        body_link, offset = self.model.lumped_into[link_name]
        index = self.link_index[body_link]
        if index == -1:
            frame = self.root_pose()
        else:
            state = self.client.getLinkState(self.body, index, computeForwardKinematics=True)
            frame = Pose(tuple(state[4]), tuple(state[5]))
        return compose(frame, offset) if offset != IDENTITY else frame

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
        """World-frame (linear velocity of any URDF link frame's origin, lumped ones included; angular velocity)."""
        index = self.link_index[self.model.lumped_into[link_name][0]]
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
        body_link, offset = self.model.lumped_into[link_name]
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

    def release_joint(self, joint_name: str):
        """No motor: PyBullet holds every joint with a velocity motor unless told otherwise."""
        self.set_joint_velocity(joint_name, 0.0, 0.0)


class Engine:
    def __init__(self, physics: PhysicsConfig = PhysicsConfig(), connection_mode: int = pybullet.DIRECT):
        self.client = CachingBulletClient(connection_mode=connection_mode)
        self.physics = physics
        self._configure()
        self.steps = 0
        self.robots: Dict[str, SpawnedRobot] = {}
        self.world_bodies: Dict[str, int] = {}
        self.dynamic_world_bodies: Dict[str, int] = {}  # those with mass, which the physics moves
        # PyBullet body -> link index -> Gazebo's "model::link::collision" of the collision it holds.
        self.collision_names: Dict[int, Dict[int, str]] = {}
        self._initial: Dict[int, _InitialState] = {}
        # Per body, the model frame seen from the centre of mass where PyBullet places a base.
        self._root_from_com: Dict[int, Pose] = {}

    def _configure(self):
        self.client.setTimeStep(self.physics.max_step_size)
        self.client.setGravity(*self.physics.gravity)
        # Same inputs, same contacts: keeps two runs (and two tests) identical.
        # Friction along two tangent directions, as ODE's pyramid model that Gazebo uses: Bullet's default cone
        # friction made four-wheel skid-steer bases turn in place by fits and starts (yaw rate 0.08 to 0.8 rad/s
        # for a steady 0.8 command).
        self.client.setPhysicsEngineParameter(deterministicOverlappingPairs=1, enableConeFriction=0)

    def restart(self):
        """An empty world at sim time 0, as a fresh Engine; the caller builds the models again.

        reset_simulation goes through here rather than restoring poses: Bullet keeps contact caches and
        solver warm-start state that a restore does not reset, so only a rebuild repeats a run bit for bit.
        """
        self.client.resetSimulation()
        self._configure()
        self.steps = 0
        self.robots.clear()
        self.world_bodies.clear()
        self.dynamic_world_bodies.clear()
        self.collision_names.clear()
        self._initial.clear()
        self._root_from_com.clear()

    @property
    def sim_time(self) -> float:
        return self.steps * self.physics.max_step_size

    def step(self, count: int = 1, after_each: Sequence[Callable[[], None]] = ()):
        """``count`` physics steps; each of ``after_each`` (recorders of per-step state, then the plugins that act
        on every step) is called after every one, with ``sim_time`` already that step's."""
        step = self.client.stepSimulation  # one attribute lookup: BulletClient builds a partial on each
        if after_each:
            for _ in range(count):
                step()
                self.steps += 1
                for call in after_each:
                    call()
        else:
            for _ in range(count):
                step()
            self.steps += count

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
        for joint_name in robot.movable_joints:
            robot.release_joint(joint_name)
        self.robots[robot.name] = robot
        # A link holding several collisions is named by its first: Bullet reports contacts per link.
        self.collision_names[robot.body] = {robot.link_index[link]: f"{robot.name}::{link}::{names[0]}"
                                            for link, names in robot.model.collision_names().items()
                                            if names and link in robot.link_index}
        self._root_from_com[robot.body] = robot.root_from_com
        self._remember_initial_state(robot.body)

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
        self.collision_names.pop(body, None)
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

    def reset_world(self):
        """Every model back to its spawn pose and joint positions, at rest (Gazebo's reset_world)."""
        for body in self._initial:
            self._restore_initial_state(body)

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
            joints = client.getJointStates(body, range(count)) if count else []
            states[name] = BodyState(client.getBasePositionAndOrientation(body), client.getBaseVelocity(body),
                                     [(position, velocity) for position, velocity, *_ in joints])
        return states

    def restore_body_state(self, name: str, state: "BodyState"):
        body = self.body_of(name)
        self.client.resetBasePositionAndOrientation(body, *state.pose)
        self.client.resetBaseVelocity(body, *state.velocity)
        for index, (position, velocity) in enumerate(state.joints):
            self.client.resetJointState(body, index, position, velocity)

    def _restore_initial_state(self, body: int):
        initial = self._initial[body]
        self.client.resetBasePositionAndOrientation(body, initial.position, initial.orientation)
        self.client.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0))
        for index, position in initial.joint_positions.items():
            self.client.resetJointState(body, index, position, 0.0)

    def close(self):
        if self.client is not None:
            self.client.disconnect()
            self.client = None

    def _load_urdf(self, model: RobotModel, pose: Pose) -> int:
        # PyBullet reads URDF only from a file; a private temp file keeps the source tree untouched.
        handle, path = tempfile.mkstemp(prefix="mbot_sim_bridge_", suffix=".urdf")
        try:
            with os.fdopen(handle, "w") as urdf_file:
                urdf_file.write(model.pybullet_urdf)
            flags = (pybullet.URDF_MERGE_FIXED_LINKS | pybullet.URDF_USE_INERTIA_FROM_FILE
                     | pybullet.URDF_USE_IMPLICIT_CYLINDER)
            # PyBullet's URDF importer prints its link merging; keep it out of the node's output.
            with open(os.devnull, "w") as devnull, c_stdout_to(devnull):
                body = self.client.loadURDF(path, flags=flags, useFixedBase=model.anchored)
        except pybullet.error as error:
            raise ModelError(f"PyBullet could not load model '{model.name}': {error}") from None
        finally:
            os.unlink(path)
        com = compose(pose, inverse(root_from_com(self.client, body)))
        self.client.resetBasePositionAndOrientation(body, com.position, com.orientation)
        return body

    def set_surfaces(self, robot: SpawnedRobot, driven_joints: Sequence[str]):
        """Friction of every link; ball casters (see RobotModel.caster_links) are those on joints not driven."""
        robot.driven_joints = tuple(driven_joints)
        casters = set(robot.model.caster_links(driven_joints))
        if casters:
            _logger.info(f"{robot.name}: ball-caster contact (frictionless) for {', '.join(sorted(casters))}")
        for link_name, index in robot.link_index.items():
            self._set_surface(robot, link_name, index, caster=link_name in casters)

    def _set_surface(self, robot: SpawnedRobot, link_name: str, index: int, caster: bool):
        mu = DEFAULT_MU
        # sdformat keeps a lumped link's <gazebo reference> surface on the collisions it brings to its parent
        # (a base_link lumped into a base_footprint root keeps its mu); Bullet has one friction per link.
        frictions = {}
        for name, (body_link, _) in robot.model.lumped_into.items():
            link = robot.model.links.get(name)
            if body_link != link_name or link is None or (name != link_name and not link.collision_kinds):
                continue
            mu1, mu2 = link.gazebo_tag("mu1"), link.gazebo_tag("mu2")
            values = [_friction(v, robot.name, name) for v in (mu1, mu2) if v is not None]
            if len(values) == 2 and values[0] != values[1]:
                warn_once(_logger, f"{robot.name}: link '{name}' has mu1 {mu1} and mu2 {mu2}; Bullet's friction "
                                   "is isotropic, the smaller is used")
            if values:
                frictions[name] = min(values)
        if len(set(frictions.values())) > 1:
            warn_once(_logger, f"{robot.name}: links lumped into '{link_name}' have different friction ("
                               f"{', '.join(f'{name} {value:g}' for name, value in sorted(frictions.items()))}); "
                               "Bullet has one per link, the smallest is used")
        if frictions:
            mu = min(frictions.values())
        if caster:
            mu = 0.0
        self.client.changeDynamics(robot.body, index, lateralFriction=mu, spinningFriction=0.0,
                                   rollingFriction=0.0, restitution=0.0)

    def _remember_initial_state(self, body: int):
        position, orientation = self.client.getBasePositionAndOrientation(body)
        joints = {index: self.client.getJointState(body, index)[0]
                  for index in range(self.client.getNumJoints(body))}
        self._initial[body] = _InitialState(tuple(position), tuple(orientation), joints)
