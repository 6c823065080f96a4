"""What every emulated Gazebo plugin is: a ``Plugin`` built from its ``<plugin>`` (and ``<sensor>``) element.

A Gazebo plugin is one core module (a ``Plugin`` subclass that reads its tags, drives joints or senses, and
computes its outputs, with no ROS), one ROS module (a subclass that adds the publishers and subscribers)
and one line in the plugin table (``core/plugin_table.py``). The Simulation builds every plugin the same way, calls
``update(now)`` when its timer is due and ``on_step`` after each physics step if it asks for it.
"""
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Optional, Protocol, Sequence, Tuple
from xml.etree import ElementTree

import numpy as np

from .body_wrenches import BodyWrenches
from .clock import UpdateTimer
from .names import plugin_namespace
from .errors import ConfigError
from .parameters import Parameters
from .params import Param, PluginParams

if TYPE_CHECKING:  # for the annotations only: neither imports this module
    from .cameras.render_scene import RenderScene
    from .engine import Engine, SpawnedRobot


class PluginHost(Protocol):
    """What a plugin uses of the simulation that runs it (``simulation.Simulation``), and nothing more: plugins
    depend on this, not on the Simulation, which builds them."""
    engine: "Engine"
    parameters: Parameters
    package_uris: Callable[[str], str]
    wrenches: BodyWrenches
    call_in_loop: Callable[..., Any]

    @property
    def sim_time(self) -> float: ...

    @property
    def step_size(self) -> float: ...

    @property
    def render_scene(self) -> "RenderScene": ...

    def random_stream(self, model_name: str, key: str) -> np.random.Generator: ...


@dataclass
class SpawnedModel:
    """A robot spawned from URDF, with the plugins built from its <gazebo> blocks."""
    name: str
    namespace: str
    robot: "SpawnedRobot"
    plugins: List["Plugin"] = field(default_factory=list)


@dataclass
class PluginContext:
    simulation: PluginHost
    model: SpawnedModel
    link: Optional[str] = None  # a sensor plugin's link (the <gazebo reference>), lumped or not

    @property
    def engine(self):
        return self.simulation.engine

    @property
    def robot(self):
        return self.model.robot

    def random_stream(self, key: str) -> np.random.Generator:
        """This model's random stream named ``key`` (a sensor name): independent of other models and of spawn
        order, and re-derived by reset_simulation."""
        return self.simulation.random_stream(self.model.name, key)

    def where(self, element: Optional[ElementTree.Element]) -> str:
        """'model NAME:LINE' for messages about an element of the model's description."""
        return self.model.robot.model.document.where(element)


@dataclass
class WorldPluginContext(PluginContext):
    """A world plugin's context: ``model`` holds the world's name and its plugins, without a robot."""
    path: str = ""

    def where(self, element: Optional[ElementTree.Element]) -> str:
        return f"world '{self.model.name}' ({self.path})"


class Plugin:
    """Base of every emulated plugin, model or sensor."""

    # Gazebo's class name, for messages ("GazeboRosDiffDrive(ns = /): ..."); the Python class name if empty.
    GAZEBO_CLASS = ""
    PARAMS: Tuple[Param, ...] = ()
    # Tags Gazebo reads without effect; accepted with one INFO line.
    IGNORED_TAGS: Tuple[str, ...] = ()
    # () for a model plugin; the <sensor type="..."> values a sensor plugin goes inside.
    SENSOR_TYPES: Tuple[str, ...] = ()
    # The enclosing <sensor>'s own values (SDF names and defaults) that a sensor plugin reads.
    SENSOR_PARAMS: Tuple[Param, ...] = ()

    timer: UpdateTimer  # set by every subclass
    needs_every_step = False
    # How an absent or empty <robotNamespace> resolves (core/names.py): MODEL, SENSOR, ROOT or IMU_SENSOR.
    NAMESPACE_RULE: Optional[str] = None
    driven_joints: Tuple[str, ...] = ()
    joint_states_published: Tuple[str, ...] = ()

    def __init__(self, context: PluginContext, element: ElementTree.Element,
                 sensor: Optional[ElementTree.Element] = None):
        self.context = context
        self.element = element
        self.sensor = sensor

    @property
    def label(self) -> str:
        """How messages name the plugin, as gazebo_ros's own do: 'GazeboRosDiffDrive(ns = /)'."""
        return f"{self.GAZEBO_CLASS or type(self).__name__}(ns = {self.namespace_tag() or self.context.model.name})"

    @classmethod
    def plugin_element(cls, filename: str, name: str, **tags: str) -> ElementTree.Element:
        """The ``<plugin>`` block a Gazebo user would write, for a plugin the simulator adds by itself; the tags
        are checked against PARAMS, so the block reads back as written."""
        unknown = sorted(set(tags) - {param.tag for param in cls.PARAMS})
        if unknown:
            raise ValueError(f"{cls.__name__} has no tags {', '.join(unknown)}")
        element = ElementTree.Element("plugin", name=name, filename=filename)
        for tag, text in tags.items():
            ElementTree.SubElement(element, tag).text = text
        return element

    def namespace_tag(self) -> Optional[str]:
        element = self.element.find("robotNamespace")
        return None if element is None else (element.text or "").strip()

    def robot_namespace(self) -> str:
        """The plugin's namespace, by its class's ``NAMESPACE_RULE``."""
        return plugin_namespace(self.NAMESPACE_RULE, self.namespace_tag(), self.context.model.name)

    def read_params(self, params: Sequence[Param] = None, element: ElementTree.Element = None,
                    check_unknown: bool = True) -> Dict[str, Any]:
        """The values of ``params`` (the class's PARAMS) in ``element`` (the <plugin>), or ConfigError."""
        element = self.element if element is None else element
        reader = PluginParams(element, self.label, self.IGNORED_TAGS, self.context.where(element), check_unknown)
        return reader.read(self.PARAMS if params is None else params)

    def named_joints(self, params: Dict[str, Any], tags: Sequence[str]) -> Tuple[str, ...]:
        """The joints the tags name; one the robot lacks (or has as a fixed joint), or one named by two of the
        tags, refuses the spawn, listing the movable joints."""
        robot, where = self.context.robot, f"{self.context.where(self.element)}: {self.label}"
        named: Dict[str, str] = {}
        for tag in tags:
            joint = params[tag]
            if joint not in robot.joint_index:
                movable = ", ".join(robot.movable_joints) or "none"
                what = "which is fixed" if joint in robot.model.joints else "which the robot does not have"
                raise ConfigError(f"{where}: <{tag}> names joint '{joint}', {what}; movable joints: {movable}")
            if joint in named:
                raise ConfigError(f"{where}: <{named[joint]}> and <{tag}> both name joint '{joint}'; each needs a "
                                  f"joint of its own")
            named[joint] = tag
        return tuple(params[tag] for tag in tags)

    def on_step(self, step_size: float):
        """After every physics step, when ``needs_every_step``: between the steps of a batch (``sim_time`` is
        that step's), so it does not stop the loop; what it makes for ROS waits for ``update``."""

    def step_recorder(self, now: float) -> Optional[Callable[[], None]]:
        """Before the loop steps: a call to make after each of its physics steps (it should only read state,
        as ``SpawnedRobot.link_state_recorder`` does), or None. The plugin's update then gets the recorded
        steps at the next stop of the loop, so it needs no stop of its own (``clock.EveryStopTimer``)."""
        return None

    def update(self, now: float):
        """When ``timer`` is due, with the sim time in seconds: compute the outputs into the plugin's state."""

    def idle(self, now: float):
        """When ``timer`` is due but nothing takes the outputs (the ROS layer calls it instead of ``update``
        while no one subscribes, as gazebo_ros's sensors work only then): keep what the next update needs."""

    def joints_set(self, positions: Dict[str, float]):
        """set_model_configuration put these joints at these positions, at rest, between two steps."""

    def reset(self, now: float):
        """World or simulation reset (Gazebo calls the plugin's Reset())."""
        self.timer.reset(now)

    def close(self):
        """The model is deleted or the simulation stops."""


class WorldPlugin(Plugin):
    """A Gazebo world plugin (``<plugin>`` inside ``<world>``, GZ_REGISTER_WORLD_PLUGIN): built once with the
    world, told of the deletions of models it may hold on to."""

    def model_deleted(self, name: str):
        """Model ``name`` is about to be deleted."""
