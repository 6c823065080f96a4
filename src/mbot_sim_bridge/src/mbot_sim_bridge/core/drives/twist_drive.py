"""What the four drives share (differential, planar move, skid steer, tricycle): the last cmd_vel, held for the
loop, and the odometry they report."""
import math
import threading
from typing import NamedTuple, Optional, Tuple

from ..geometry import Pose, yaw

# Upstream's pose covariance of the drives' odometry (x, y, yaw known; z, roll, pitch not).
ODOM_POSE_COVARIANCE = (1e-5, 0, 0, 0, 0, 0,
                        0, 1e-5, 0, 0, 0, 0,
                        0, 0, 1e12, 0, 0, 0,
                        0, 0, 0, 1e12, 0, 0,
                        0, 0, 0, 0, 1e12, 0,
                        0, 0, 0, 0, 0, 1e-3)


class DriveOdometry(NamedTuple):
    pose: Pose
    linear: Tuple[float, float]  # base frame (vx, vy)
    angular: float  # ωz


def yaw_rotated_velocity(world_linear, yaw: float) -> Tuple[float, float]:
    """World-frame linear velocity rotated by yaw only, as the plugins' world odometry twist is."""
    vx, vy = world_linear[0], world_linear[1]
    return math.cos(yaw) * vx + math.sin(yaw) * vy, math.cos(yaw) * vy - math.sin(yaw) * vx


def ground_truth_odometry(robot) -> DriveOdometry:
    """The root link's world pose and its twist as the drives' world odometry reports it."""
    pose = robot.root_pose()
    linear, angular = robot.root_velocity()
    return DriveOdometry(pose, yaw_rotated_velocity(linear, yaw(pose.orientation)), angular[2])


class TwistCommand:
    """The last valid cmd_vel of a drive, stored from ROS threads, read by the loop; mixed in before Plugin.

    ``set_command`` takes the ``COMMAND_AXES`` the drive reads (linear.x and angular.z; the planar move adds
    linear.y between them). With ``command_timeout`` ≥ 0 (sim seconds), ``command(now)`` is zero once no command
    came for that long, counted from the first step that saw it."""
    COMMAND_AXES: Tuple[str, ...] = ("linear.x", "angular.z")
    COMMAND_LIMIT = math.inf  # m/s and rad/s; a command beyond it is refused as a non-finite one is
    command_timeout = -1.0

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._lock = threading.Lock()
        self.stop()

    def set_command(self, *values: float) -> bool:
        """Store a body twist (m/s, rad/s); one that is not finite or beyond COMMAND_LIMIT is refused (False) and
        the last valid one stays."""
        if len(values) != len(self.COMMAND_AXES):
            raise TypeError(f"{type(self).__name__}.set_command takes {', '.join(self.COMMAND_AXES)}")
        if not all(math.isfinite(value) and abs(value) <= self.COMMAND_LIMIT for value in values):
            return False
        with self._lock:
            self._command = tuple(values)
            self._command_time = None  # stamped by the loop, in sim time, at the next step
        return True

    def command(self, now: Optional[float] = None) -> Tuple[float, ...]:
        """The command to act on at sim time ``now`` (None: the last one, whatever its age)."""
        with self._lock:
            if now is not None and self.command_timeout >= 0:
                if self._command_time is None:
                    self._command_time = now
                if now - self._command_time > self.command_timeout:
                    self._command = (0.0,) * len(self.COMMAND_AXES)
            return self._command

    def stop(self):
        with self._lock:
            self._command = (0.0,) * len(self.COMMAND_AXES)
            self._command_time: Optional[float] = None
