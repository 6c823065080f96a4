"""``libgazebo_ros_control.so`` without ROS: the tags, the default robot hardware simulation and the controller
manager, updated at ``controlPeriod`` in the loop thread.

As gazebo_ros_control's GazeboRosControlPlugin (Noetic): the controllers update when at least controlPeriod
(default: the physics step) has passed since the last update, reading the joints first; the joint commands
are written after every physics step. The ROS plugin (``plugins/gazebo_ros_control.py``) supplies the URDF
from ``robotParam``, the parameters, the controllers' ROS classes and the services.

The controllers' messages are published from ``update(now)``, which the Simulation calls after /clock
(``timer`` is due whenever a controller has filled its ``outbox`` or a running one's publish time has come), so
none is stamped ahead of the clock. Their control runs in ``on_step``, between the physics steps of a batch.
What a controller fills at the step it is due, as upstream's realtime publishers are filled (joint states,
odometry, the PID controllers' state), keeps that step's values and stamp and goes out at the loop's next stop;
the loop stops only where a controller publishes from its state at a stop (``Controller.steps_until_publish``).
"""
import sys
from typing import Dict, List, Set
from xml.etree import ElementTree

from .. import names
from ..log import get_logger, warn_once
from ..parameters import absolute_name
from ..params import Param, period
from ..plugin import Plugin
from ..description.robot_model import RobotModel, parse_robot
from .controller_table import CORE_CONTROLLERS
from .controller_manager import ControllerManager
from .hardware_interface import UNBOUNDED_EFFORT
from .robot_hw_sim import ROBOT_HW_SIMS
from .transmissions import parse_transmissions
from ..xml_values import XmlDocument

_logger = get_logger(__name__)

# controlPeriod equal to the step, to within this, counts as the step (sim time is a multiple of it).
_EPSILON = 1e-9

GAZEBO_ROS_CONTROL_PARAMS = (
    Param("robotNamespace", str, "", "namespace of the controller manager, its controllers and parameters; "
          "spawn_model sets it", warn_if_missing=False),
    Param("robotParam", str, "robot_description", "parameter holding the URDF (searched up from robotNamespace)",
          warn_if_missing=False),
    period("controlPeriod", 0.0, "controller update period (s); absent = the physics step",
           warn_if_missing=False),
    Param("robotSimType", str, "gazebo_ros_control/DefaultRobotHWSim", "robot hardware simulation",
          warn_if_missing=False, choices=tuple(ROBOT_HW_SIMS)),
    Param("legacyModeNS", bool, False, "Kinetic's absolute /gazebo_ros_control/pid_gains namespace when true "
          "(see README)", warn_if_missing=False),
    Param("eStopTopic", str, "", "std_msgs/Bool topic: true stops every joint, false restarts the controllers",
          warn_if_missing=False),
)


def _same_description(parameter_xml: str, spawned_xml: str) -> bool:
    """Whether the model was spawned from this parameter's text, as spawn_model -param sends it (parsed and
    written again, without the XML declaration and comments): its model is then reused, not parsed again."""
    if parameter_xml == spawned_xml:
        return True
    try:
        return ElementTree.tostring(ElementTree.fromstring(parameter_xml), encoding="unicode") == spawned_xml
    except ElementTree.ParseError:
        return False  # parse_robot names the fault


class _PublishSchedule:
    """The plugin's ``timer``: due when any running controller has something to publish."""

    def __init__(self, plugin: "GazeboRosControlPlugin"):
        self.plugin = plugin

    def due(self, now: float) -> bool:
        due = [loaded for loaded in self.plugin.manager.controllers if loaded.controller.outbox or (
               loaded.controller.state == "running" and loaded.controller.publish_due(now))]
        self.plugin.publish_now = due
        return bool(due)

    def steps_until_due(self, now: float, step_size: float) -> int:
        # Controllers started within a batch are counted from the next stop (a first message that much later).
        return min([loaded.controller.steps_until_publish(now, step_size) for loaded in self.plugin.manager.controllers
                    if loaded.controller.state == "running"], default=sys.maxsize)

    def reset(self, now: float):
        pass


class GazeboRosControlPlugin(Plugin):
    NAMESPACE_RULE = names.MODEL
    GAZEBO_CLASS = "GazeboRosControlPlugin"
    PARAMS = GAZEBO_ROS_CONTROL_PARAMS
    needs_every_step = True
    # Controller type -> class; the ROS plugin's classes add the controllers' topics.
    CONTROLLERS = CORE_CONTROLLERS

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.read_params()
        self.params = params
        # Absent or empty: the model name, as gazebo_ros_control (spawn_model always sets it).
        # A relative one is relative to the simulator's node, which lives at the root.
        self.namespace = "/" + self.robot_namespace().lstrip("/")
        step = context.simulation.step_size
        self.control_period = params["controlPeriod"] if self.element.find("controlPeriod") is not None else step
        if self.control_period < step - _EPSILON:
            _logger.error(f"{self.label}: Desired controller update period ({self.control_period} s) is faster than "
                          f"the gazebo simulation period ({step} s).")
        elif self.control_period > step + _EPSILON:
            _logger.warning(f"{self.label}: Desired controller update period ({self.control_period} s) is slower than "
                            f"the gazebo simulation period ({step} s).")
        parameters = context.simulation.parameters
        model = self._robot_description(params["robotParam"])
        document: XmlDocument = model.document
        transmissions = parse_transmissions(model.transmissions, document.where)
        self.urdf = model
        # Noetic reads the PID gains under the robot namespace; Kinetic's legacyModeNS (true, or absent there)
        # read them at the root. A present legacyModeNS is honoured with its Kinetic meaning.
        # Parameter names are absolute: a relative robotNamespace is relative to the simulator's node ("/").
        base = "/" + self.namespace.strip("/") if self.namespace.strip("/") else ""
        pid_namespace = ("" if params["legacyModeNS"] else base) + "/gazebo_ros_control/pid_gains"
        self.hw = ROBOT_HW_SIMS[params["robotSimType"]](
            context.robot, transmissions, self.urdf, self.label, parameters.get(base + "/joint_limits"),
            parameters.get(pid_namespace), pid_namespace)
        if not self.hw.joints:
            warn_once(_logger, f"{self.label}: the robot has no usable <transmission>; the "
                               "controller manager has no joints")
        self.driven_joints = tuple(self.hw.names)
        self.joint_states_published = tuple(self.hw.names)
        self.manager = ControllerManager(self.hw, self.CONTROLLERS.get, sorted(self.CONTROLLERS),
                                         lambda name: parameters.get(absolute_name(self.namespace, name)),
                                         self.namespace,
                                         lambda: context.simulation.sim_time)
        self.timer = _PublishSchedule(self)
        self.publish_now: List = []
        now = context.simulation.sim_time
        self.last_update = self.last_write = now
        self._engine = context.engine  # the sim time without the Simulation's property, after every step
        self.e_stop = False
        self._last_e_stop = False
        self._pinned: Dict[str, float] = {}  # joints held at set_model_configuration's positions (joints_set)

    def _robot_description(self, param_name: str) -> RobotModel:
        """The URDF in ``robotParam``, searched from the robot namespace upwards (NodeHandle::searchParam), with
        package:// resolved as spawning resolves it; the spawned model's own when there is none."""
        parameters = self.context.simulation.parameters
        name = parameters.search(self.namespace, param_name)
        if name is None:
            _logger.warning(f"{self.label}: no parameter '{param_name}' from namespace {self.namespace} upwards "
                            "(gazebo_ros_control would wait for it); using the description the model was spawned "
                            "from")
            return self.context.robot.model
        xml = self.context.simulation.package_uris(parameters.get(name))
        if _same_description(xml, self.context.robot.model.xml):
            return self.context.robot.model
        return parse_robot(xml, f"parameter {name}")

    # -- loop ------------------------------------------------------------------------------------------------
    def load_controller(self, name: str) -> bool:
        return self.manager.load(name, self.urdf)

    def on_step(self, step_size: float):
        now = self._engine.sim_time
        self.hw.e_stop_active = self.e_stop
        period = now - self.last_update
        if period >= self.control_period - _EPSILON:
            if not self.hw.read_sim():
                return
            self.last_update = now
            reset = False
            if self.e_stop:
                self._last_e_stop = True
            elif self._last_e_stop:
                reset, self._last_e_stop = True, False
            if self._pinned:
                # Before the update: a controller started by this update's switch writes no command until the
                # next one, so its joints stay held one more step.
                self._release_claimed()
            self.manager.update(now, period, reset)
        self.hw.write_sim(now - self.last_write)
        self.last_write = now
        if self._pinned:
            self._hold_pinned()

    def update(self, now: float):
        """Publish for the controllers whose time has come (the ROS plugin does the publishing, then calls this)."""
        for loaded in self.publish_now:
            loaded.controller.outbox.clear()
        self.publish_now = []

    def joints_set(self, positions):
        """The joints' new positions read exactly (readSim would unwrap a jump of more than pi), position
        commands there, and the running controllers restarted: their holds take the new positions instead of
        pulling the joints back (the bridge's choice; Gazebo's controllers fight set_model_configuration).
        Effort-driven joints no running controller drives are held there by a motor until one does: else they
        sag under gravity until the spawner starts their controller, which then holds them where they fell."""
        self.hw.joints_set(positions)
        self.manager.restart_running(self._engine.sim_time)
        claimed = self._claimed_joints()
        self._pinned = {name: position for name, position in positions.items() if name in self.hw.joints
                        and self.hw.joints[name].motor == "effort" and name not in claimed}
        self._hold_pinned()

    def _claimed_joints(self) -> Set[str]:
        return {joint for loaded in self.manager.controllers if loaded.state == "running"
                for _, joints in loaded.claimed for joint in joints}

    def _release_claimed(self):
        """Pinned joints a running controller drives are let go."""
        claimed = self._claimed_joints()
        for name in [name for name in self._pinned if name in claimed]:
            del self._pinned[name]
            self.context.robot.release_joint(name)

    def _hold_pinned(self):
        for name, position in self._pinned.items():
            self.context.robot.set_joint_position(name, position, UNBOUNDED_EFFORT)

    def reset(self, now: float):
        # gazebo_ros_control resets its update times; the controllers' own clocks restart too, so a
        # reset_simulation (sim time back to 0) does not silence their topics until the old time comes back.
        self.last_update = self.last_write = now
        self.hw.forget_motors()
        self._pinned = {}
        for loaded in self.manager.controllers:
            loaded.controller.restart_clock(now)

    def close(self):
        self.manager.unload_all()
