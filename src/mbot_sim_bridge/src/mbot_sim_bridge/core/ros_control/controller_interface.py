"""controller_interface::Controller<T>, and reading a controller's parameters as NodeHandle::param does."""
import math
import sys
from dataclasses import dataclass
from typing import Any, Callable, List, Optional, Sequence, Tuple

from ..log import get_logger, warn_once
from ..description.robot_model import RobotModel
from .hardware_interface import JOINT_STATE
from .robot_hw_sim import DefaultRobotHWSim

_logger = get_logger(__name__)


_MISSING = object()


def param(params: dict, path: str, default=_MISSING, kind: type = float, where: str = ""):
    """A controller parameter by its slash path ("linear/x/max_velocity"), as NodeHandle::param reads it:
    ints are accepted for doubles; a value of the wrong type keeps the default, with a warning."""
    value = params
    for key in path.split("/"):
        if not isinstance(value, dict) or key not in value:
            return None if default is _MISSING else default
        value = value[key]
    if kind is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if kind is int and isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, kind):
        return value
    warn_once(_logger, f"{where}: parameter '{path}' is {value!r}, not a {kind.__name__}; using {default!r}")
    return None if default is _MISSING else default


@dataclass
class LoadContext:
    """What a controller gets besides its parameters: the robot's URDF (None if it could not be read) and its
    parameter namespace (for messages)."""
    urdf: Optional[RobotModel]
    namespace: str
    clock: Callable[[], float]  # the sim time (s), readable from any thread


class Controller:
    """controller_interface::Controller<T>: the state machine and the claimed resources."""

    INTERFACE = JOINT_STATE

    def __init__(self, name: str, hw: DefaultRobotHWSim, params: dict, context: LoadContext):
        self.name = name
        self.hw = hw
        self.params = params
        self.state = "initialized"
        self.claimed: List[str] = []
        # What update() filled for the ROS layer at the step it was due, as (sim time, sample): upstream's
        # controllers fill their realtime publishers' messages in update, and another thread sends them. The
        # loop sends these at its next stop (at most MAX_BATCH_SIM_SECONDS later), so they need no stop of their
        # own; the plugin then empties the list.
        self.outbox: List[Tuple[float, Any]] = []

    def handle(self, joint: str):
        handle = self.hw.handle(joint, self.INTERFACE)
        if self.INTERFACE != JOINT_STATE and joint not in self.claimed:
            self.claimed.append(joint)
        return handle

    def finite_command(self, joints: Sequence[str], values: Sequence[float]) -> bool:
        """Whether every value of a command is a finite number. NaN or inf reaching the physics engine would turn
        the model's state into NaN and disturb every other model, so such a command is ignored, said once."""
        for joint, value in zip(joints, values):
            if not math.isfinite(value):
                warn_once(_logger, f"controller '{self.name}': command {value} for joint '{joint}' is not a finite "
                                   "number; ignored (the joint keeps its last command)")
                return False
        return True

    def start_request(self, now: float):
        self.starting(now)
        self.state = "running"

    def stop_request(self, now: float):
        self.stopping(now)
        self.state = "stopped"

    def starting(self, now: float):
        pass

    def stopping(self, now: float):
        pass

    def update(self, now: float, period: float):
        pass

    def publish_due(self, now: float) -> bool:
        """Whether the ROS layer has something to publish now from the controller's state at this stop of the
        loop (the bridge publishes after /clock); ``outbox`` holds what was filled at earlier steps."""
        return False

    def steps_until_publish(self, now: float, step_size: float) -> int:
        """Physics steps until ``publish_due`` can next be true: the loop runs the updates between the steps of
        its batches and stops there. A controller that publishes from a stop says when; what an update makes at
        any step (a goal's end, the ``outbox``) goes out when the loop next stops."""
        return sys.maxsize

    def restart_clock(self, now: float):
        """Sim time was reset: start the publish and timeout clocks again from ``now``."""

    def close(self):
        pass
