"""control_toolbox::Pid, as the PID controllers and gazebo_ros_control's pid_gains use it."""
import math
from typing import Optional

from ..log import get_logger, warn_once

_logger = get_logger(__name__)

GAINS = ("p", "i", "d")


def clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


class Pid:
    """control_toolbox::Pid: p, i, d, i_clamp (or i_clamp_min/max), antiwindup; computeCommand as upstream."""

    def __init__(self, p=0.0, i=0.0, d=0.0, i_max=0.0, i_min=0.0, antiwindup=False):
        self.p, self.i, self.d, self.i_max, self.i_min, self.antiwindup = p, i, d, i_max, i_min, antiwindup
        self.reset()

    @classmethod
    def from_params(cls, params, namespace: str, quiet: bool = False) -> Optional["Pid"]:
        """Pid::init(nh): None (with upstream's error unless quiet) when there is no ``p``; None with an error
        naming the gain when a gain is not a finite number (the clamps may be infinite), which upstream takes
        and which would turn every command into NaN."""
        if not isinstance(params, dict) or "p" not in params:
            if not quiet:
                _logger.error(f"No p gain specified for pid.  Namespace: {namespace}")
            return None
        for key in ("p", "i", "d", "i_clamp", "i_clamp_min", "i_clamp_max"):
            value = params.get(key, 0.0)
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not number or math.isnan(value) or (key in GAINS and math.isinf(value)):
                _logger.error(f"{namespace}/{key} is {value!r}: a PID gain must be a finite number"
                              f"{'' if key in GAINS else ' (or infinite)'}; the PID is not loaded")
                return None
        i_clamp = abs(float(params.get("i_clamp", 0.0)))
        i_max, i_min = i_clamp, -i_clamp
        if "i_clamp_min" in params:
            i_min = -abs(float(params["i_clamp_min"]))
        if "i_clamp_max" in params:
            i_max = abs(float(params["i_clamp_max"]))
        if params.get("publish_state"):
            warn_once(_logger, f"{namespace}/publish_state: the PID's own control_msgs/PidState topic is not "
                               "published (the controllers' JointControllerState is)")
        return cls(float(params["p"]), float(params.get("i", 0.0)), float(params.get("d", 0.0)), i_max, i_min,
                   bool(params.get("antiwindup", False)))

    def reset(self):
        # Upstream's reset() leaves the last error "valid" at 0, so the first derivative sees the whole error.
        self.p_error_last = self.i_error = self.d_error = self.command = 0.0
        self.valid_p_error_last = True

    def compute(self, error: float, dt: float, error_dot: Optional[float] = None) -> float:
        if dt == 0.0 or not math.isfinite(error):
            return 0.0
        if error_dot is None:
            error_dot = self.d_error
            if dt > 0.0:
                if self.valid_p_error_last:
                    error_dot = (error - self.p_error_last) / dt
                self.p_error_last = error
                self.valid_p_error_last = True
        self.d_error = error_dot
        if not math.isfinite(error_dot):
            return 0.0
        self.i_error += dt * error
        if self.antiwindup and self.i != 0:
            bounds = sorted((self.i_min / self.i, self.i_max / self.i))
            self.i_error = clamp(self.i_error, bounds[0], bounds[1])
        i_term = self.i * self.i_error
        if not self.antiwindup:
            i_term = clamp(i_term, self.i_min, self.i_max)
        self.command = self.p * error + i_term + self.d * error_dot
        return self.command
