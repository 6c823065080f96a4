"""The simulation, without ROS: the engine and world, the spawned models with their plugins, the update
schedule, spawn/delete/reset in Gazebo's order, and the random streams of the noisy sensors.

The ROS node runs ``advance`` in its loop and publishes /clock from the ``before_updates`` hook; the unit
tests run the same ``advance`` with the plugins' core classes. Plugins are built from a registry
(Gazebo file name -> class) handed in: the plugin table's core classes (``plugin_table.CORE_PLUGINS``) or the
ROS layer's registry derived from it, so the core never imports the ROS plugin layer.
"""
import hashlib
import sys
from dataclasses import replace
from typing import Callable, Dict, List, Mapping, NamedTuple, Optional, Sequence, Set, Tuple
from xml.etree import ElementTree

import numpy as np
import pybullet

from .added_plugins import ADDED_JOINT_STATE_RATE, joint_state_blocks, mimic_blocks
from .body_wrenches import WORLD_FRAMES, BodyWrenches, requested_job
from .engine import Engine, StepFault, check_state, frame_velocity
from .errors import ConfigError, ModelError, PluginLeftOut
from .geometry import IDENTITY, Pose, Vector, compose, inverse, rotate
from . import entity_properties, physics_properties
from .entity_properties import JointProperties, LinkProperties
from .joints import joint_efforts
from .joints.joint_efforts import JointEfforts
from .joints.model_configuration import requested_positions
from .lights import Lights, world_lights
from .log import get_logger, warn_once
from .parameters import Parameters
from .plugin import Plugin, PluginContext, SpawnedModel, WorldPlugin, WorldPluginContext
from .cameras.render_scene import RenderScene
from .description.robot_model import RobotModel
from .description.world_description import ArticulatedModel, ModelDescription, WorldDescription
from .viewer import Viewer
from .world_bodies import load_world

_logger = get_logger(__name__)

# Above this many links a spawn takes seconds (PyBullet's URDF import): said first, so a pause is explained.
LARGE_MODEL_LINKS = 1000
# Sim time covered by one batch of physics steps at most, so requests and shutdown are served promptly.
MAX_BATCH_SIM_SECONDS = 0.01


class ModelProperties(NamedTuple):
    """get_model_properties' answer: link (body) names, collision (geom) names, joint names, static."""
    body_names: List[str]
    geom_names: List[str]
    joint_names: List[str]
    is_static: bool


# Called before the due plugins update: (sim time, whether any plugin is due). The node publishes /clock there.
BeforeUpdates = Callable[[float, bool], None]


class Simulation:
    def __init__(self, world: WorldDescription, registry: Mapping[str, type], seed: int = 0,
                 connection_mode: int = pybullet.DIRECT, joint_state_rate: float = ADDED_JOINT_STATE_RATE,
                 parameters: Optional[Parameters] = None, package_uris: Callable[[str], str] = str):
        """``parameters``: what plugins read from the parameter server (gazebo_ros_control, tf_prefix);
        ``package_uris``: resolves package:// in a robot description read from there, as spawning does."""
        self.world = world  # the description the simulation was loaded from
        self.engine = Engine(world.physics, connection_mode)
        self.viewer = Viewer(self.engine) if connection_mode == pybullet.GUI else None
        self.registry = registry
        self.parameters = parameters if parameters is not None else Parameters()
        self.package_uris = package_uris
        self.seed = seed
        self.joint_state_rate = joint_state_rate
        self.paused = False
        # How work a plugin's service asks for from another thread runs in the loop's thread: the node hands in
        # its own (node.call_in_loop); without a node (tests, benches) the caller is the loop's thread.
        self.call_in_loop: Callable[..., object] = lambda function, timeout=None: function()
        # Changes whenever models come or go or are moved from outside: what caches of their poses check.
        self.version = 0
        self.models: Dict[str, SpawnedModel] = {}
        # World models (from the .world and spawn_sdf_model) as described, by name.
        self.world_models: Dict[str, ModelDescription] = {}
        # SDF models with joints, sensors or plugins (also in ``models``, as robots), by name.
        self.sdf_robots: Dict[str, ArticulatedModel] = {}
        self._streams: Dict[str, Tuple[np.random.SeedSequence, np.random.Generator]] = {}
        # What was built, in order (a WorldDescription, or the name of a robot), for reset_simulation's rebuild.
        self._build_order: List[object] = []
        self._plugins: List[Plugin] = []
        self._every_step_calls: List[Callable[[], None]] = []  # on_step of the plugins that need every step
        self._recording: List[Plugin] = []
        self._frozen: Set[str] = set()  # models the physics turned NaN, held until a reset
        self._render_scene: Optional[RenderScene] = None
        self.wrenches = BodyWrenches()  # apply_body_wrench's jobs
        self.joint_efforts = JointEfforts()  # apply_joint_effort's
        # How to undo each link's and joint's properties set from outside, for reset_world: (model, name) -> undo.
        self._property_undo: Dict[Tuple[str, str], Callable[[], None]] = {}
        self._joint_limits: Dict[Tuple[str, str], Tuple[float, float]] = {}  # set by set_joint_properties
        self.lights = Lights(world_lights(world.others))
        self.sensor_updates: Dict[Plugin, int] = {}  # updates of each sensor plugin so far (performance_metrics)
        # The world's own plugins, held as a model's are (their owner named after the world), built after its models.
        self.world_plugins = SpawnedModel(world.name, "/", None)
        self.add_world(world)
        self.world_plugins.plugins = [plugin for element in world.plugins
                                      for plugin in self._create_world_plugin(element)]
        self._schedule()

    # -- state -------------------------------------------------------------------------------------------------
    @property
    def sim_time(self) -> float:
        return self.engine.sim_time

    @property
    def step_size(self) -> float:
        return self.engine.physics.max_step_size

    @property
    def render_scene(self) -> RenderScene:
        """What the cameras see, made when the first one asks (a world without cameras pays nothing)."""
        if self._render_scene is None:
            self._render_scene = RenderScene(self)
        return self._render_scene

    def model_names(self) -> List[str]:
        return self.engine.model_names()

    def random_stream(self, model_name: str, key: str) -> np.random.Generator:
        """A generator seeded from the world seed and the stable key "model/key"; one per key."""
        name = f"{model_name}/{key}"
        if name not in self._streams:
            # A hash of the name, not the spawn order or Python's salted hash(), keys the stream.
            digest = hashlib.sha256(name.encode()).digest()
            sequence = np.random.SeedSequence(self.seed, spawn_key=(int.from_bytes(digest[:8], "little"),))
            self._streams[name] = (sequence, np.random.Generator(np.random.PCG64(sequence)))
        return self._streams[name][1]

    # -- spawn and delete ----------------------------------------------------------------------------------------
    def add_world(self, description: WorldDescription, namespace: str = "/") -> List[str]:
        """Build the models of a world (the loaded one, or one spawn_sdf_model wraps); returns the names added.
        Models with joints, sensors or plugins are spawned as robots, in ``namespace``."""
        duplicates = [model.name for model in description.models + description.robots
                      if model.name in self.model_names()]
        if duplicates:
            raise ModelError(f"SpawnModel: Failure - entity already exists: {', '.join(duplicates)}")
        loaded = load_world(self.engine.client, description)
        self.engine.add_world(loaded)
        for model in description.models:
            if model.name in loaded.bodies:
                self.world_models[model.name] = model
        self._build_order.append(description)
        self.version += 1
        for articulated in description.robots:
            self.spawn_robot(articulated.robot, articulated.name, compose(articulated.pose, articulated.root_in_model),
                             namespace)
            self.sdf_robots[articulated.name] = articulated
            if articulated.joint_positions:  # a saved world's: reset_world goes back to the model's own, as Gazebo
                self.set_model_configuration(articulated.name, list(articulated.joint_positions),
                                             list(articulated.joint_positions.values()))
        return list(loaded.bodies) + [articulated.name for articulated in description.robots]

    def spawn_robot(self, model: RobotModel, name: str, pose: Pose = IDENTITY, namespace: str = "/") -> SpawnedModel:
        """Put a parsed robot in the engine with its plugins; on any error, leave nothing of it behind."""
        if len(model.links) > LARGE_MODEL_LINKS:
            _logger.info(f"model '{name}': {len(model.links)} links; PyBullet takes a while to load that many")
        robot = self.engine.spawn_robot(model, name, pose, namespace, driven_joints=None)
        spawned = SpawnedModel(name, namespace, robot)
        try:
            spawned.plugins = self._build_plugins(spawned)
            self.engine.set_surfaces(robot, [joint for plugin in spawned.plugins for joint in plugin.driven_joints])
        except BaseException:
            for plugin in spawned.plugins:
                plugin.close()
            self.engine.remove(name)
            raise
        self.models[name] = spawned
        self._build_order.append(name)
        self.version += 1
        self._schedule()
        if self.viewer is not None:
            self.viewer.show_robot(robot)
        _logger.info(f"spawned '{name}' ({len(robot.link_index)} links, {len(robot.movable_joints)} movable joints, "
                     f"{len(spawned.plugins)} plugins) at {tuple(round(v, 3) for v in pose.position)}")
        return spawned

    def delete(self, name: str):
        if name not in self.model_names():
            raise ModelError(f"DeleteModel: model '{name}' does not exist")
        self._forget(name)
        self.engine.remove(name)
        self.version += 1

    def _forget(self, name: str):
        """Everything but the engine's body of model ``name`` gone: its plugins closed, its streams and wrenches."""
        spawned = self.models.pop(name, None)
        if spawned is not None:
            for plugin in spawned.plugins:
                plugin.close()
                self.sensor_updates.pop(plugin, None)
            if self.viewer is not None:
                self.viewer.forget_robot(spawned.robot)
            for key in [key for key in self._streams if key.startswith(name + "/")]:
                del self._streams[key]
            self._build_order.remove(name)
            self._frozen.discard(name)
            self._schedule()
        self.world_models.pop(name, None)
        self.sdf_robots.pop(name, None)
        self.wrenches.clear(name)
        self.joint_efforts.clear(name)
        for key in [key for key in self._property_undo if key[0] == name]:
            del self._property_undo[key]
        self._joint_limits = {key: value for key, value in self._joint_limits.items() if key[0] != name}
        for plugin in list(self.world_plugins.plugins):
            self._guarded(plugin, plugin.model_deleted, name)

    # -- wrenches from outside (apply_body_wrench) ---------------------------------------------------------------
    def apply_body_wrench(self, body: str, reference_frame: str, reference_point, force, torque, start_time: float,
                          duration: float):
        """Schedule a wrench on link ``body`` ("model::link"), as gazebo_ros's apply_body_wrench; the request is
        checked and made a job by ``body_wrenches.requested_job`` (ModelError with upstream's message)."""
        self.wrenches.add(requested_job(body, reference_frame, reference_point, force, torque, start_time, duration,
                                        self.sim_time, self.link_names, self._link_pose, self._entity_pose))

    def clear_body_wrenches(self, body: str):
        model, _, link = body.partition("::")
        self.wrenches.clear(model, link)

    # -- efforts on joints from outside (apply_joint_effort) ---------------------------------------------------------
    def apply_joint_effort(self, joint_name: str, effort: float, start_time: float, duration: float):
        """Schedule an effort on a robot's joint ("joint" or "model::joint"), as gazebo_ros's apply_joint_effort
        (see ``joints.joint_efforts``; ModelError with upstream's message)."""
        movable = [(name, spawned.robot.movable_joints) for name, spawned in self.models.items()]
        self.joint_efforts.add(joint_efforts.requested_job(joint_name, effort, start_time, duration, self.sim_time,
                                                           movable, self._effort_limit))

    def _effort_limit(self, model: str, joint: str) -> Optional[float]:
        described = self.models[model].robot.model.joints[joint]
        return described.effort if described.has_limit and described.effort > 0 else None

    def _apply_joint_efforts(self):
        for (model, joint), effort in self.joint_efforts.due(self.sim_time).items():
            if model not in self._frozen:
                self.models[model].robot.set_joint_effort(joint, effort)

    def link_names(self, model: str) -> List[str]:
        """The links a model has in the physics (a robot's after lumping, a world model's own)."""
        if model in self.models:
            return list(self.models[model].robot.link_index)
        if model in self.world_models:
            return [link.name for link in self.world_models[model].links]
        return []

    def _link_pose(self, model: str, link: str) -> Pose:
        if model in self.models:
            return self.models[model].robot.link_world_pose(link)
        description = self.world_models[model]
        in_model = compose(inverse(description.pose), next(item.pose for item in description.links
                                                           if item.name == link))
        return compose(self.engine.model_pose(model), in_model)

    def _entity_pose(self, name: str) -> Optional[Pose]:
        """A model's or a "model::link"'s world pose, or None when there is no such entity."""
        if name in self.model_names():
            return self.engine.model_pose(name)
        model, _, link = name.partition("::")
        return self._link_pose(model, link) if link in self.link_names(model) else None

    def _entity_twist(self, name: str) -> Tuple[Vector, Vector]:
        """World (linear velocity of the frame's origin, angular velocity) of a model or an existing "model::link"."""
        if name in self.model_names():
            return self.engine.model_velocity(name)
        model, _, link = name.partition("::")
        if model in self.models:
            return self.models[model].robot.link_world_velocity(link)
        return frame_velocity(self.engine.client, self.engine.body_of(model), self._link_pose(model, link).position)

    def link_state(self, link_name: str, reference_frame: str) -> Tuple[Pose, Vector, Vector]:
        """get_link_state: a "model::link"'s pose and (linear, angular) velocity relative to any entity, as
        gazebo_ros computes them (``_relative``)."""
        model, _, link = link_name.partition("::")
        if not link or link not in self.link_names(model):
            raise ModelError("GetLinkState: link not found, did you forget to scope the link by model name?")
        return self._relative(reference_frame, self._link_pose(model, link), *self._entity_twist(link_name),
                              "GetLinkState: reference reference_frame not found, did you forget to scope the link "
                              "by model name?")

    def model_state(self, name: str, relative_entity_name: str) -> Tuple[Pose, Vector, Vector]:
        """get_model_state: a model's pose and (linear, angular) velocity relative to any entity (``_relative``)."""
        if name not in self.model_names():
            raise ModelError("GetModelState: model does not exist")
        return self._relative(relative_entity_name, self.engine.model_pose(name), *self.engine.model_velocity(name),
                              "GetModelState: reference relative_entity_name not found, did you forget to scope the "
                              "body by model name?")

    def _relative(self, frame_name: str, pose: Pose, linear, angular, not_found: str) -> Tuple[Pose, Vector, Vector]:
        """A world state seen from entity ``frame_name`` as gazebo_ros's get_*_state compute it: the pose relative
        to the frame, the velocities the differences with the frame's, rotated into it (no ω × r term, so a point
        at rest in a turning frame has no velocity in it). A world frame keeps them; another unknown name raises
        ModelError(``not_found``)."""
        frame = self._entity_pose(frame_name)
        if frame is None:
            if frame_name in WORLD_FRAMES:
                return pose, tuple(linear), tuple(angular)
            raise ModelError(not_found)
        frame_linear, frame_angular = self._entity_twist(frame_name)
        back = inverse(frame)
        return (compose(back, pose), rotate(back.orientation, np.subtract(linear, frame_linear)),
                rotate(back.orientation, np.subtract(angular, frame_angular)))

    def reference_pose(self, frame_name: str, not_found: str) -> Pose:
        """The world pose of a request's reference frame: any model or "model::link", the world for "", "world",
        "map" and "/map"; ModelError(``not_found``) for another name."""
        frame = self._entity_pose(frame_name)
        if frame is None:
            if frame_name in WORLD_FRAMES:
                return IDENTITY
            raise ModelError(not_found)
        return frame

    def set_link_state(self, link_name: str, reference_frame: str, pose: Pose, linear, angular):
        """set_link_state: link "model::link" put at ``pose`` with the (linear, angular) velocity of its origin,
        all given in entity ``reference_frame`` as gazebo_ros takes them: the pose composed with the frame's, the
        velocities minus the frame's, not rotated (upstream's arithmetic, kept).

        Bullet moves a link of an articulated body only through its joints, so the whole model moves as one body
        to put the link there, its joint positions unchanged (Gazebo moves the link alone and its joints pull it
        and the rest together over the next steps). The model then turns about the link's origin with the given
        twist: a robot's root link keeps the joints' velocities, as Gazebo's Link::SetLinearVel leaves the other
        links', another link's model stops its joints, so that the link has exactly the given twist. A robot fixed
        to the world (a root link "world") is refused: moving its links means moving its joints."""
        model, _, link = link_name.partition("::")
        if not link or link not in self.link_names(model):
            raise ModelError("SetLinkState: link does not exist")
        what = f"SetLinkState: link '{link_name}'"
        check_state(what, pose, linear, angular)  # as sent: transformed, 1e300 would turn inf and NaN
        frame = self._entity_pose(reference_frame)
        if frame is not None:
            frame_linear, frame_angular = self._entity_twist(reference_frame)
            pose = compose(frame, pose)
            linear, angular = tuple(np.subtract(linear, frame_linear)), tuple(np.subtract(angular, frame_angular))
        elif reference_frame not in WORLD_FRAMES:
            raise ModelError("SetLinkState: failed")
        check_state(what, pose, linear, angular)
        spawned = self.models.get(model)
        if spawned is not None and spawned.robot.model.anchored:
            raise ModelError(f"{what}: model '{model}' is fixed to the world, so its links move only through its "
                             "joints (set_model_configuration); nothing was changed")
        model_pose = self.engine.model_pose(model)
        link_in_model = compose(inverse(model_pose), self._link_pose(model, link))
        on_root = spawned is None or spawned.robot.link_index[spawned.robot.model.lumped_into[link][0]] == -1
        self.engine.move_model(model, compose(pose, inverse(link_in_model)), pose.position, linear, angular,
                               stop_joints=not on_root)
        self.version += 1

    # -- physics (physics_properties) ----------------------------------------------------------------------------------
    def ode_config(self) -> physics_properties.OdeConfig:
        return physics_properties.ode_config(self.engine.physics, self.engine.solver_iterations)

    def set_physics(self, time_step: float, max_update_rate: float, gravity, ode: physics_properties.OdeConfig):
        """set_physics_properties (physics_properties' module docstring); ModelError naming a bad value."""
        physics, iterations, ignored = physics_properties.requested_physics(self.engine.physics, time_step,
                                                                            max_update_rate, gravity, ode)
        if ignored:
            warn_once(_logger, f"SetPhysicsProperties: {', '.join(ignored)}: no Bullet counterpart; ignored")
        self.engine.set_physics(physics, iterations)
        self._schedule()  # plugins that act every step take the new step size

    # -- link and joint properties (entity_properties) ---------------------------------------------------------------
    def _physics_link(self, link_name: str, not_found: str) -> Tuple[str, str, int, Optional[int]]:
        """(model, link, body, Bullet link index) of a "model::link"; the index is None for a link of a world model
        with several links (welded into the body's base). ModelError(``not_found``) when there is no such link."""
        model, _, link = link_name.partition("::")
        if not link or link not in self.link_names(model):
            raise ModelError(not_found)
        body = self.engine.body_of(model)
        if model in self.models:
            return model, link, body, self.models[model].robot.link_index[link]
        return model, link, body, -1 if len(self.world_models[model].links) == 1 else None

    def link_properties(self, link_name: str) -> LinkProperties:
        """get_link_properties (entity_properties' module docstring)."""
        model, link, body, index = self._physics_link(
            link_name, "GetLinkProperties: link not found, did you forget to scope the link by model name?")
        if index is None:
            described = next(item for item in self.world_models[model].links if item.name == link)
            ixx, ixy, ixz, iyy, iyz, izz = described.inertia
            return LinkProperties(described.inertial_pose, True, described.mass, ixx, ixy, ixz, iyy, iyz, izz)
        mass, _, (ixx, iyy, izz), position, orientation = self.engine.client.getDynamicsInfo(body, index)[:5]
        com = Pose(tuple(position), tuple(orientation))  # in the Bullet link's frame: a world model's base is its own
        if model in self.world_models:
            described = self.world_models[model]
            com = compose(inverse(compose(inverse(described.pose), described.links[0].pose)), com)
        return LinkProperties(com, not self.engine.weightless(body, index), mass, ixx, 0.0, 0.0, iyy, 0.0, izz)

    def set_link_properties(self, link_name: str, requested: LinkProperties):
        """set_link_properties: mass, the moments about the inertia's axes and gravity_mode (entity_properties'
        module docstring); ModelError with upstream's message for an unknown link, naming the value for a bad one."""
        model, link, body, index = self._physics_link(
            link_name, "SetLinkProperties: link not found, did you forget to scope the link by model name?")
        if index is None:
            raise ModelError(f"SetLinkProperties: link '{link_name}': the links of world model '{model}' are welded "
                             "into one body here; only a one-link model's properties can change")
        if model in self.world_models and self.world_models[model].static:
            raise ModelError(f"SetLinkProperties: link '{link_name}': model '{model}' is static (it has no mass and "
                             "does not move); nothing was changed")
        current = self.link_properties(link_name)
        mass, moments, frame_changed = entity_properties.checked_link_properties(link_name, requested, current)
        if frame_changed:
            warn_once(_logger, f"SetLinkProperties: link '{link_name}': Bullet keeps a link's centre of mass and "
                               "inertia axes; the mass and the moments about its axes are set, the rest ignored")
        if (model, link) not in self._property_undo:
            weightless = self.engine.weightless(body, index)

            def undo():
                self._set_mass(model, body, index, current.mass, (current.ixx, current.iyy, current.izz))
                self.engine.set_weightless(body, index, weightless)
            self._property_undo[(model, link)] = undo
        self._set_mass(model, body, index, mass, moments)
        self.engine.set_weightless(body, index, not requested.gravity_mode)

    def _set_mass(self, model: str, body: int, index: int, mass: float, moments):
        self.engine.client.changeDynamics(body, index, mass=mass, localInertiaDiagonal=moments)
        if model in self.models:  # the wheel contact model shares the robot's weight among its wheels
            self.engine.set_surfaces(self.models[model].robot, self.models[model].robot.driven_joints)

    def _joint(self, joint_name: str, not_found: str) -> Tuple[str, str]:
        movable = [(name, spawned.robot.movable_joints) for name, spawned in self.models.items()]
        found = joint_efforts.find_joint(joint_name, movable)
        if found is None:
            raise ModelError(not_found)
        return found

    def joint_properties(self, joint_name: str) -> JointProperties:
        """get_joint_properties: the joint's type (upstream always says REVOLUTE), the damping set_joint_properties
        gave it, its position and rate."""
        model, joint = self._joint(joint_name, "GetJointProperties: joint not found")
        robot = self.models[model].robot
        position, rate, _ = robot.joint_state([joint])[0]
        damping = self.engine.joint_damping(robot.body, robot.joint_index[joint])
        return JointProperties(entity_properties.JOINT_TYPES[robot.model.joints[joint].type], [damping], [position],
                               [rate])

    def set_joint_properties(self, joint_name: str, config):
        """set_joint_properties with ODEJointProperties ``config`` (entity_properties' module docstring)."""
        model, joint = self._joint(joint_name, "SetJointProperties: joint not found")
        robot = self.models[model].robot
        index = robot.joint_index[joint]
        client = self.engine.client
        lower, upper = client.getJointInfo(robot.body, index)[8:10]
        if lower > upper:  # no limits; Bullet's stops, once set, are put out of reach instead (they stay)
            lower, upper = -entity_properties.NO_STOP, entity_properties.NO_STOP
        limits = self._joint_limits.get((model, joint), (lower, upper))
        settings = entity_properties.checked_joint_settings(joint_name, config, *limits)
        if settings.ignored:
            warn_once(_logger, f"SetJointProperties: joint '{joint_name}': {', '.join(settings.ignored)} have no "
                               "Bullet counterpart; ignored")
        if (model, joint) not in self._property_undo:
            def undo():
                self.engine.set_joint_damping(robot.body, index, 0.0)
                client.changeDynamics(robot.body, index, jointLowerLimit=lower, jointUpperLimit=upper)
                self._joint_limits.pop((model, joint), None)
            self._property_undo[(model, joint)] = undo
        if settings.damping is not None:
            self.engine.set_joint_damping(robot.body, index, settings.damping)
        if settings.limits is not None:
            client.changeDynamics(robot.body, index, jointLowerLimit=settings.limits[0],
                                  jointUpperLimit=settings.limits[1])
            self._joint_limits[(model, joint)] = settings.limits
        if settings.motor is not None:
            robot.set_joint_velocity(joint, *settings.motor)

    def model_properties(self, name: str) -> ModelProperties:
        """get_model_properties: the links and joints the physics has (a robot's after fixed-joint lumping, as
        Gazebo's), their collisions by sdformat's names; no nested models."""
        if name not in self.model_names():
            raise ModelError("GetModelProperties: model does not exist")
        if name in self.models:
            robot = self.models[name].robot
            collisions = robot.model.collision_names()
            return ModelProperties(list(robot.link_index), [collision for link in robot.link_index
                                                            for collision in collisions.get(link, [])],
                                   list(robot.joint_index), False)
        description = self.world_models[name]
        return ModelProperties([link.name for link in description.links],
                               [shape.name for link in description.links for shape in link.collisions], [],
                               description.static)

    def _apply_wrenches(self):
        for (model, link), (force, torque) in self.wrenches.due(self.sim_time).items():
            if model in self._frozen:
                continue
            if model in self.models:
                self.engine.apply_link_wrench(self.models[model].robot.body, self.models[model].robot.link_index[link],
                                              force, torque)
            else:
                self.engine.apply_link_wrench(self.engine.body_of(model), -1, force, torque)

    def set_model_state(self, name: str, pose: Pose, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
        """Move a model and set its velocity (set_model_state, set from outside the physics)."""
        self.engine.set_model_state(name, pose, linear, angular)
        self.version += 1

    def set_model_configuration(self, name: str, joint_names: Sequence[str], positions: Sequence[float]) -> List[str]:
        """set_model_configuration: joints of robot ``name`` set exactly, at rest, before its next step, its
        plugins told (ros_control's controllers then start from, or hold, the new positions); returns the
        requested joints the model has none of (ignored, as Gazebo ignores them). A world model has no joints."""
        if name not in self.model_names():
            raise ModelError("SetModelConfiguration: model does not exist")
        spawned = self.models.get(name)
        joints, movable = (spawned.robot.model.joints, spawned.robot.movable_joints) if spawned else ({}, ())
        wanted, missing = requested_positions(joints, movable, joint_names, positions)
        if wanted:
            self.engine.set_joint_positions(spawned.robot, wanted)
            self.version += 1
            for plugin in list(spawned.plugins):
                self._guarded(plugin, plugin.joints_set, wanted)
        return missing

    def _build_plugins(self, spawned: SpawnedModel) -> List[Plugin]:
        plugins = spawned.plugins  # filled in place: a spawn refused half-way closes those built so far
        model = spawned.robot.model
        for element in model.plugins:
            plugins.extend(self._create_plugin(spawned, element, None, None))
        for link_name, sensor in model.sensors():
            elements = sensor.findall("plugin")
            if not elements:
                warn_once(_logger, f"model '{spawned.name}': sensor '{sensor.get('name')}' on link '{link_name}' has "
                                   "no ROS plugin; nothing is published for it")
            for element in elements:
                plugins.extend(self._create_plugin(spawned, element, sensor, link_name))
        for element in mimic_blocks(model, plugins):
            plugins.extend(self._create_plugin(spawned, element, None, None))
        for element in joint_state_blocks(spawned.robot.movable_joints, plugins, spawned.namespace,
                                          self.joint_state_rate):
            plugins.extend(self._create_plugin(spawned, element, None, None))
        return plugins

    def _create_plugin(self, spawned: SpawnedModel, element: ElementTree.Element,
                       sensor: Optional[ElementTree.Element], link_name: Optional[str]) -> List[Plugin]:
        filename = element.get("filename", "")
        plugin_class = self.registry.get(filename)
        where = spawned.robot.model.document.where(element)
        if plugin_class is None:
            what = (f"sensor '{sensor.get('name')}' (type {sensor.get('type')}) on link '{link_name}': "
                    if sensor is not None else "")
            warn_once(_logger, f"{where}: model '{spawned.name}': {what}plugin '{element.get('name')}' ({filename}) is "
                               "not emulated by the bridge; ignored")
            return []
        if issubclass(plugin_class, WorldPlugin):
            warn_once(_logger, f"{where}: model '{spawned.name}': {filename} is a world plugin (it goes inside "
                               "<world>); ignored here, as Gazebo would not load it")
            return []
        if bool(plugin_class.SENSOR_TYPES) != (sensor is not None):
            kind = "a sensor plugin (it goes inside a <sensor>)" if plugin_class.SENSOR_TYPES else "a model plugin"
            warn_once(_logger, f"{where}: model '{spawned.name}': {filename} is {kind}; ignored here, as "
                               "Gazebo would not load it")
            return []
        if sensor is not None and sensor.get("type") not in plugin_class.SENSOR_TYPES:
            wanted = '" or "'.join(plugin_class.SENSOR_TYPES)
            raise ConfigError(f"{where}: model '{spawned.name}': {filename} needs <sensor type=\"{wanted}\">, but "
                              f"sensor '{sensor.get('name')}' has type \"{sensor.get('type')}\"")
        context = PluginContext(self, spawned, link_name)
        try:
            return [plugin_class(context, element, sensor)]
        except PluginLeftOut as error:  # a name another plugin holds: the model goes on without this one
            _logger.warning(f"{where}: {error}")
            return []

    def _create_world_plugin(self, element: ElementTree.Element) -> List[Plugin]:
        """A ``<plugin>`` of the world, as Gazebo loads one: an unknown or model plugin is said once and left
        out; one whose tags are wrong is refused with one error, and the world goes on without it."""
        filename, where = element.get("filename", ""), f"{self.world.path}: world '{self.world.name}'"
        plugin_class = self.registry.get(filename)
        if plugin_class is None or not issubclass(plugin_class, WorldPlugin):
            what = "is not emulated by the bridge" if plugin_class is None else "is not a world plugin"
            warn_once(_logger, f"{where}: plugin '{element.get('name')}' ({filename}) {what}; ignored")
            return []
        try:
            return [plugin_class(WorldPluginContext(self, self.world_plugins, path=self.world.path), element)]
        except ConfigError as error:
            _logger.error(f"{where}: plugin '{element.get('name')}' ({filename}) not loaded: {error}")
            return []
        except PluginLeftOut as error:
            _logger.warning(f"{where}: {error}")
            return []

    def _schedule(self):
        self._plugins = [plugin for name, spawned in self.models.items() if name not in self._frozen
                         for plugin in spawned.plugins]
        self._plugins += self.world_plugins.plugins
        self._every_step_calls = [self._every_step_call(plugin) for plugin in self._plugins if plugin.needs_every_step]
        self._recording = [plugin for plugin in self._plugins if type(plugin).step_recorder is not Plugin.step_recorder]

    # -- stepping ------------------------------------------------------------------------------------------------
    def steps_to_next_event(self) -> int:
        """Physics steps until the next plugin timer can be due. Plugins that act on every step do so between the
        steps of a batch, so they do not end it."""
        now, step = self.sim_time, self.step_size
        batch = max(1, int(round(MAX_BATCH_SIM_SECONDS / step)))
        for jobs in (self.wrenches, self.joint_efforts):
            job_steps = jobs.steps_until_next(now, step)
            if job_steps is not None:
                batch = min(batch, job_steps)
        # A timer is part of its plugin: one that raises (an overflowing period) disables the plugin, not the loop.
        return min([batch] + [self._guarded(plugin, plugin.timer.steps_until_due, now, step) or sys.maxsize
                              for plugin in self._plugins])

    def advance(self, max_steps: int, before_updates: Optional[BeforeUpdates] = None) -> int:
        """Step up to the next plugin event or ``max_steps``, then run the due updates; returns the steps taken."""
        count = max(1, min(max_steps, self.steps_to_next_event()))
        if self.wrenches.pending() or self.wrenches.applied:
            self._apply_wrenches()
        if self.joint_efforts.pending():
            self._apply_joint_efforts()
        per_step = []
        for plugin in self._recording:
            recorder = self._guarded(plugin, plugin.step_recorder, self.sim_time)
            if recorder is not None:
                per_step.append(self._every_step_call(plugin, recorder))
        per_step += self._every_step_calls
        start = self.engine.steps
        try:
            self.engine.step(count, per_step)
        except StepFault as fault:
            self._freeze([fault.model], f"its part of the physics step failed ({fault})")
        except Exception as error:  # Bullet's own step: no one model to blame, so the world is built again
            failed_at = self.sim_time
            self._freeze(self.engine.models_not_finite(), "the physics step made its state NaN")
            self.engine.steps = start + count  # the rest of the batch is skipped, so sim time goes on
            _logger.error(f"the physics step at {failed_at:.3f} s failed ({type(error).__name__}: {error}); the world "
                          f"was built again with every model's state, and sim time moved on to {self.sim_time:.3f} s "
                          "without physics")
        else:
            broken = self.engine.models_not_finite()
            if broken:
                self._freeze(broken, "the physics step made its state NaN")
        count = self.engine.steps - start  # fewer than asked when a model's part of the step failed
        now = self.sim_time
        due = [plugin for plugin in self._plugins if self._guarded(plugin, plugin.timer.due, now)]
        if before_updates is not None:
            before_updates(now, bool(due))
        counts = self.sensor_updates
        for plugin in due:
            self._guarded(plugin, plugin.update, now)
            if plugin.sensor is not None:
                counts[plugin] = counts.get(plugin, 0) + 1
        if self.viewer is not None:
            self.viewer.follow()
        return count

    def _freeze(self, names: Sequence[str], reason: str):
        """Models whose state the physics made NaN (or whose part of a step raised: ``reason``) go back to their
        spawn state (a robot with its plugins stopped) until a reset; one that fails again by itself is deleted,
        so the recovery is not repeated every step. Bullet has by then spread the NaN through its broadphase (left
        alone, every other model sinks through the ground, and even a static ground plane reads NaN), so the
        world is rebuilt with every other moving model's state carried over."""
        for name in [name for name in names if name in self._frozen]:
            self.delete(name)
            _logger.error(f"model '{name}': {reason} again after it was put back at its spawn pose, with nothing "
                          "driving it; it is deleted")
        names = [name for name in names if name in self.model_names()]
        moving = [name for name in self.engine.model_names() if name not in names and not (
            name in self.world_models and self.world_models[name].static)]
        kept = {name: state for name, state in self.engine.body_states(moving).items() if state.finite}
        steps, time_offset = self.engine.steps, self.engine.time_offset
        self._rebuild()
        self.engine.steps, self.engine.time_offset = steps, time_offset
        for name, state in kept.items():
            if name in self.engine.model_names():  # not one the rebuild had to remove
                self.engine.restore_body_state(name, state)
        self._frozen.update(names)
        self._schedule()
        self.version += 1
        for name in names:
            _logger.error(f"model '{name}': {reason}; it is put back at its spawn pose and frozen (a robot's plugins "
                          "stopped) until reset_world or reset_simulation")

    def step(self, count: int, before_updates: Optional[BeforeUpdates] = None):
        """Exactly ``count`` physics steps, with every plugin event on the way."""
        while count > 0:
            count -= self.advance(count, before_updates)

    def _every_step_call(self, plugin: Plugin, recorder: Optional[Callable[[], None]] = None) -> Callable[[], None]:
        """``plugin.on_step`` (or ``recorder``, what its step_recorder returned) as a call for ``Engine.step`` to
        make after every step of a batch; after a failure (the plugin is then disabled) the rest of the batch skips
        it."""
        step_size, model = self.step_size, plugin.context.model

        def guarded():
            if plugin in model.plugins:  # a failed plugin is removed from its model's few
                # _guarded written out: this runs after every physics step, where each extra call costs
                try:
                    if recorder is None:
                        plugin.on_step(step_size)
                    else:
                        recorder()
                except Exception as error:  # the plugin boundary, as in _guarded
                    self._disable(plugin, error)
        return guarded

    def _guarded(self, plugin: Plugin, method, *arguments):
        """``method(*arguments)``; a plugin that raises is disabled (None is returned), and the simulation and
        other models go on."""
        try:
            return method(*arguments)
        except Exception as error:  # the plugin boundary: a failure inside one plugin must not stop the others
            self._disable(plugin, error)

    def _disable(self, plugin: Plugin, error: Exception):
        """A plugin that raised: logged once, closed and dropped."""
        owner = "world" if isinstance(plugin, WorldPlugin) else "model"
        _logger.error(f"{owner} '{plugin.context.model.name}': plugin {plugin.label} failed and is disabled: "
                      f"{type(error).__name__}: {error}")
        _logger.debug(f"the failure of {plugin.label}", exc_info=error)
        plugin.context.model.plugins.remove(plugin)
        try:
            plugin.close()
        except Exception:  # closing a broken plugin may fail too; it is gone either way
            _logger.debug(f"closing {plugin.label} failed", exc_info=True)
        self._schedule()

    # -- reset ---------------------------------------------------------------------------------------------------
    def reset(self, simulation: bool):
        """reset_simulation (sim time back to 0, the world rebuilt, random streams re-derived) or reset_world
        (models back to their spawn state; sim time runs on)."""
        if simulation:
            self._rebuild()
            for sequence, generator in self._streams.values():
                generator.bit_generator.state = np.random.PCG64(sequence).state
        else:
            for undo in self._property_undo.values():
                undo()
            self._forget_set_properties()
            self.engine.reset_world()
        self._frozen.clear()
        # Resets repair what service calls left: wrenches and efforts "until cleared" too.
        self.wrenches = BodyWrenches()
        self.joint_efforts = JointEfforts()
        self._schedule()
        self.version += 1
        for plugin in list(self._plugins):
            self._guarded(plugin, plugin.reset, self.sim_time)

    def _rebuild(self):
        """Every model built again in its original order, as a new run would: see Engine.restart. A model that
        cannot be built again (a mesh file gone since it was spawned) is removed, with one error, and the rest
        is built again without it; for a world the unit is what was loaded at once (the .world file's models, or
        one spawn_sdf_model's)."""
        while True:
            self.engine.restart()
            self._forget_set_properties()  # the models are loaded as described
            names, error = self._build_again()
            if not names:
                return
            for name in names:
                self._forget(name)
            self._schedule()
            _logger.error(f"model{'s' if len(names) > 1 else ''} {', '.join(repr(name) for name in names)}: could not "
                          f"be built again ({type(error).__name__}: {error}); removed")

    def _build_again(self) -> Tuple[List[str], Optional[Exception]]:
        """The models of ``_build_order`` built in the restarted engine; returns the names of the first entry that
        failed (none built after it) and its error."""
        for entry in self._build_order:
            if isinstance(entry, str):
                try:
                    self.engine.respawn(self.models[entry].robot)
                except Exception as error:  # the model's own description or files; contained to it
                    return [entry], error
                if self.viewer is not None:
                    self.viewer.show_robot(self.models[entry].robot)
            else:
                kept = tuple(model for model in entry.models if model.name in self.world_models)
                try:
                    self.engine.add_world(load_world(self.engine.client, replace(entry, models=kept)))
                except Exception as error:  # as above
                    return [model.name for model in kept], error
        return [], None

    def _forget_set_properties(self):
        self._property_undo.clear()
        self._joint_limits.clear()

    def __enter__(self) -> "Simulation":
        return self

    def __exit__(self, *exception):
        self.close()

    def close(self):
        for name in list(self.models):
            for plugin in self.models.pop(name).plugins:
                plugin.close()
        for plugin in self.world_plugins.plugins:
            plugin.close()
        self.world_plugins.plugins = []
        self._schedule()
        self.engine.close()
