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

from .added_plugins import joint_state_blocks, mimic_blocks
from .body_wrenches import WORLD_FRAMES, BodyWrenches, requested_job
from .engine import Engine, frame_velocity
from .errors import ConfigError, ModelError
from .geometry import IDENTITY, Pose, Vector, compose, inverse, rotate
from .joints.model_configuration import requested_positions
from .log import get_logger, warn_once
from .parameters import Parameters
from .plugin import Plugin, PluginContext, SpawnedModel, WorldPlugin, WorldPluginContext
from .cameras.render_scene import RenderScene
from .description.robot_model import RobotModel
from .description.world_description import ModelDescription, WorldDescription
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
                 connection_mode: int = pybullet.DIRECT, joint_state_rate: float = 100.0,
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
        self._streams: Dict[str, Tuple[np.random.SeedSequence, np.random.Generator]] = {}
        # What was built, in order (a WorldDescription, or the name of a robot), for reset_simulation's rebuild.
        self._build_order: List[object] = []
        self._plugins: List[Plugin] = []
        self._every_step_calls: List[Callable[[], None]] = []  # on_step of the plugins that need every step
        self._recording: List[Plugin] = []
        self._frozen: Set[str] = set()  # models the physics turned NaN, held until a reset
        self._render_scene: Optional[RenderScene] = None
        self.wrenches = BodyWrenches()  # apply_body_wrench's jobs
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
    def add_world(self, description: WorldDescription) -> List[str]:
        """Build the models of a world (the loaded one, or one spawn_sdf_model wraps); returns the names added."""
        duplicates = [model.name for model in description.models if model.name in self.model_names()]
        if duplicates:
            raise ModelError(f"SpawnModel: Failure - entity already exists: {', '.join(duplicates)}")
        loaded = load_world(self.engine.client, description)
        self.engine.add_world(loaded)
        for model in description.models:
            if model.name in loaded.bodies:
                self.world_models[model.name] = model
        self._build_order.append(description)
        self.version += 1
        return list(loaded.bodies)

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
        spawned = self.models.pop(name, None)
        if spawned is not None:
            for plugin in spawned.plugins:
                plugin.close()
            if self.viewer is not None:
                self.viewer.forget_robot(spawned.robot)
            for key in [key for key in self._streams if key.startswith(name + "/")]:
                del self._streams[key]
            self._build_order.remove(name)
            self._frozen.discard(name)
            self._schedule()
        self.world_models.pop(name, None)
        self.wrenches.clear(name)
        for plugin in list(self.world_plugins.plugins):
            self._guarded(plugin, plugin.model_deleted, name)
        self.engine.remove(name)
        self.version += 1

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
        gazebo_ros computes them (the velocities are the differences with the frame's, rotated into it)."""
        model, _, link = link_name.partition("::")
        if not link or link not in self.link_names(model):
            raise ModelError("GetLinkState: link not found, did you forget to scope the link by model name?")
        pose, (linear, angular) = self._link_pose(model, link), self._entity_twist(link_name)
        frame = self._entity_pose(reference_frame)
        if frame is None:
            if reference_frame in WORLD_FRAMES:
                return pose, tuple(linear), tuple(angular)
            raise ModelError("GetLinkState: reference reference_frame not found, did you forget to scope the link by "
                             "model name?")
        frame_linear, frame_angular = self._entity_twist(reference_frame)
        back = inverse(frame)
        return (compose(back, pose), rotate(back.orientation, np.subtract(linear, frame_linear)),
                rotate(back.orientation, np.subtract(angular, frame_angular)))

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
        plugins: List[Plugin] = []
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
        return [plugin_class(context, element, sensor)]

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
        wrench_steps = self.wrenches.steps_until_next(now, step)
        if wrench_steps is not None:
            batch = min(batch, wrench_steps)
        # A timer is part of its plugin: one that raises (an overflowing period) disables the plugin, not the loop.
        return min([batch] + [self._guarded(plugin, plugin.timer.steps_until_due, now, step) or sys.maxsize
                              for plugin in self._plugins])

    def advance(self, max_steps: int, before_updates: Optional[BeforeUpdates] = None) -> int:
        """Step up to the next plugin event or ``max_steps``, then run the due updates; returns the steps taken."""
        count = max(1, min(max_steps, self.steps_to_next_event()))
        if self.wrenches.pending() or self.wrenches.applied:
            self._apply_wrenches()
        recorders = [self._guarded(plugin, plugin.step_recorder, self.sim_time) for plugin in self._recording]
        per_step = [recorder for recorder in recorders if recorder is not None]
        per_step += self._every_step_calls
        self.engine.step(count, per_step)
        broken = self.engine.models_not_finite()
        if broken:
            self._freeze(broken)
        now = self.sim_time
        due = [plugin for plugin in self._plugins if self._guarded(plugin, plugin.timer.due, now)]
        if before_updates is not None:
            before_updates(now, bool(due))
        for plugin in due:
            self._guarded(plugin, plugin.update, now)
        if self.viewer is not None:
            self.viewer.follow()
        return count

    def _freeze(self, names: Sequence[str]):
        """Models whose state the physics made NaN go back to their spawn state (a robot with its plugins stopped)
        until a reset; one that turns NaN again by itself is deleted, so the recovery is not repeated every
        step. Bullet has by then spread the NaN through its broadphase (left alone, every other model sinks
        through the ground, and even a static ground plane reads NaN), so the world is rebuilt with every other
        moving model's state carried over."""
        for name in [name for name in names if name in self._frozen]:
            self.delete(name)
            _logger.error(f"model '{name}': the physics made its state NaN again after it was put back at its spawn "
                          "pose, with nothing driving it; it is deleted")
        names = [name for name in names if name in self.model_names()]
        moving = [name for name in self.engine.model_names() if name not in names and not (
            name in self.world_models and self.world_models[name].static)]
        kept = {name: state for name, state in self.engine.body_states(moving).items() if state.finite}
        steps = self.engine.steps
        self._rebuild()
        self.engine.steps = steps
        for name, state in kept.items():
            self.engine.restore_body_state(name, state)
        self._frozen.update(names)
        self._schedule()
        self.version += 1
        for name in names:
            _logger.error(f"model '{name}': the physics step made its state NaN; it is put back at its spawn pose "
                          "and frozen (a robot's plugins stopped) until reset_world or reset_simulation")

    def step(self, count: int, before_updates: Optional[BeforeUpdates] = None):
        """Exactly ``count`` physics steps, with every plugin event on the way."""
        while count > 0:
            count -= self.advance(count, before_updates)

    def _every_step_call(self, plugin: Plugin) -> Callable[[], None]:
        """``plugin.on_step`` as a call for ``Engine.step`` to make after every step of a batch; after a failure
        (the plugin is then disabled) the rest of the batch skips it."""
        step_size, model = self.step_size, plugin.context.model

        def on_step():
            if plugin in model.plugins:  # a failed plugin is removed from its model's few
                # _guarded written out: this runs after every physics step, where each extra call costs
                try:
                    plugin.on_step(step_size)
                except Exception as error:  # the plugin boundary, as in _guarded
                    self._disable(plugin, error)
        return on_step

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
            self.engine.reset_world()
        self._frozen.clear()
        self.wrenches = BodyWrenches()  # resets repair what service calls left: wrenches "until cleared" too
        self._schedule()
        self.version += 1
        for plugin in list(self._plugins):
            self._guarded(plugin, plugin.reset, self.sim_time)

    def _rebuild(self):
        """Every model built again in its original order, as a new run would: see Engine.restart."""
        self.engine.restart()
        for entry in self._build_order:
            if isinstance(entry, str):
                self.engine.respawn(self.models[entry].robot)
                if self.viewer is not None:
                    self.viewer.show_robot(self.models[entry].robot)
            else:
                kept = tuple(model for model in entry.models if model.name in self.world_models)
                self.engine.add_world(load_world(self.engine.client, replace(entry, models=kept)))

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
