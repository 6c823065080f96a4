"""joint_state_controller/JointStateController: ``publish_rate`` (required), ``joints``, ``extra_joints``. Its
update fills the ``outbox`` at the publish rate; the ROS layer (``plugins/ros_controllers.py``) publishes."""
from typing import List

from ..log import get_logger
from .controller_manager import ControllerInitError
from .hardware_interface import JOINT_STATE
from .controller_interface import Controller, param

_logger = get_logger(__name__)


class JointStateController(Controller):
    INTERFACE = JOINT_STATE

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        names = params.get("joints")
        self.joint_names = list(names) if isinstance(names, list) else hw.names_with(JOINT_STATE)
        rate = param(params, "publish_rate", None, float, name)
        if rate is None:
            raise ControllerInitError("Parameter 'publish_rate' not set")
        self.publish_rate = rate
        self.joints = [self.handle(joint) for joint in self.joint_names]
        self.extra = self._extra_joints(params.get("extra_joints"))
        self.last_publish = None

    def _extra_joints(self, specification) -> List[tuple]:
        """(name, position, velocity, effort) of each valid ``extra_joints`` entry; bad ones logged and skipped."""
        if specification is None:
            return []
        if not isinstance(specification, list):
            _logger.error("Extra joints specification is not an array. Ignoring.")
            return []
        extra = []
        for element in specification:
            if not isinstance(element, dict):
                _logger.error("Extra joint specification is not a struct, but rather "
                              f"'{type(element).__name__}'. Ignoring.")
                continue
            if "name" not in element:
                _logger.error("Extra joint does not specify name. Ignoring.")
                continue
            joint = str(element["name"])
            if joint in self.joint_names or joint in [entry[0] for entry in extra]:
                _logger.warning(f"Joint state interface already contains specified extra joint '{joint}'.")
                continue
            values = []
            for key, label in (("position", "position"), ("velocity", "velocity"), ("effort", "effort")):
                value = element.get(key, 0.0)
                if not isinstance(value, float):
                    _logger.error(f"Extra joint '{joint}' does not specify a valid default {label}. Ignoring.")
                    break
                values.append(value)
            else:
                extra.append((joint, *values))
        return extra

    def starting(self, now):
        if self.last_publish is None:
            # Once only, so the rate holds through restarts; 1.001 periods back publishes on the first cycle.
            self.last_publish = now - 1.001 / self.publish_rate if self.publish_rate > 0 else now

    def restart_clock(self, now):
        if self.last_publish is not None:
            self.last_publish = None
            if self.state == "running":
                self.starting(now)

    def update(self, now, period):
        # Upstream checks its publish time in update and fills its realtime publisher there.
        if self.publish_rate > 0 and self.last_publish + 1.0 / self.publish_rate < now:
            self.last_publish += 1.0 / self.publish_rate
            self.outbox.append((now, self.states()))

    def states(self):
        """(names, positions, velocities, efforts) with the extra joints' fixed values last."""
        names = self.joint_names + [entry[0] for entry in self.extra]
        return (names, [j.position for j in self.joints] + [e[1] for e in self.extra],
                [j.velocity for j in self.joints] + [e[2] for e in self.extra],
                [j.effort for j in self.joints] + [e[3] for e in self.extra])
