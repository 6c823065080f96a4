"""The demo's tour of a world in lockstep: the robot drives a scripted rectangle and two arcs closed-loop on /odom,
stepping the simulation itself between commands, while a Recorder keeps its path (and, with ``scan_points``, the
lidar's hits through TF). ``./mbot demo`` draws what it recorded; batch scenarios import only this module (it
leaves out the demo's plotting and arm imports)."""
import bisect
import math
import sys
import threading
import time

import numpy
import rospy
import tf2_ros
from geometry_msgs.msg import Twist
from mbot_sim_bridge.lockstep import LockstepClient
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

# The tour, in the robot's own terms: metres forward, or degrees counter-clockwise turned in place or on an
# arc (turns of at most 90 degrees, so the heading error never wraps). It stays inside the play ground's
# free rectangle (x -1.5..3.5, y -1.5..1.5) and inside the room.
TOUR = (("forward", 2.2), ("turn", 90), ("forward", 1.0), ("turn", 90), ("forward", 2.2), ("turn", 90),
        ("forward", 1.0), ("turn", 90), ("arc", 90), ("arc", 90))
LINEAR_SPEED, TURN_SPEED, MIN_TURN_SPEED = 0.4, 0.8, 0.1
HEADING_GAIN = 2.0  # rad/s of command per rad of heading error
PROGRESS_PERIOD = 0.5  # wall seconds between progress updates (2 s when the output is not a terminal)
CONTROL_PERIOD = 0.05  # sim seconds between two commands (rounded to whole physics steps)
SEGMENT_SIM_TIMEOUT = 60.0
WALL_TIMEOUT = 600.0
STEP_WALL_TIMEOUT = 30.0  # for one control period's /odom to arrive


def _yaw(orientation) -> float:
    q = orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Recorder:
    """The robot's path from /odom and the lidar's hits from /scan, in the odom frame (without ``scan_points``,
    the path only: no TF listener deserializing every /tf in this process)."""

    def __init__(self, sim: LockstepClient, scan_points: bool = True):
        self.arrived = threading.Condition()
        self.stamps, self.path, self.headings, self.scan_points = [], [], [], []
        self.scans = 0
        # Connected both ways before the first step, so no message of the tour is missed.
        self.subscribers = [sim.subscriber("/odom", Odometry, self._on_odometry)]
        if scan_points:
            self.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(120))
            self.tf_listener = tf2_ros.TransformListener(self.tf_buffer)
            self.subscribers.append(sim.subscriber("/scan", LaserScan, self._on_scan))

    def _on_odometry(self, message):
        with self.arrived:
            position = message.pose.pose.position
            self.stamps.append(message.header.stamp.to_sec())
            self.path.append((position.x, position.y))
            self.headings.append(_yaw(message.pose.pose.orientation))
            self.arrived.notify_all()

    def _on_scan(self, message):
        # The transform at the scan's stamp may need odometry of the next control step: this waits (in sim time)
        # for it on the subscriber's own thread while the tour goes on.
        try:
            transform = self.tf_buffer.lookup_transform("odom", message.header.frame_id, message.header.stamp,
                                                        rospy.Duration(1.0))
        except (tf2_ros.LookupException, tf2_ros.ExtrapolationException, tf2_ros.ConnectivityException):
            return
        ranges = numpy.asarray(message.ranges)
        angles = message.angle_min + numpy.arange(len(ranges)) * message.angle_increment
        hit = numpy.isfinite(ranges)
        t, q = transform.transform.translation, transform.transform.rotation
        yaw = _yaw(q)
        x = ranges[hit] * numpy.cos(angles[hit] + yaw) + t.x
        y = ranges[hit] * numpy.sin(angles[hit] + yaw) + t.y
        with self.arrived:
            self.scans += 1
            self.scan_points.extend(zip(x.tolist(), y.tolist()))

    def pose_at(self, sim_time: float, timeout: float):
        """(stamp, x, y, yaw) of the last odometry stamped at or before ``sim_time``, once one stamped after it has
        arrived: one connection delivers in order, so the answer does not depend on how fast messages travel."""
        with self.arrived:
            if not self.arrived.wait_for(lambda: self.stamps and self.stamps[-1] > sim_time, timeout):
                raise RuntimeError(f"no /odom stamped after {sim_time:.3f} s arrived within {timeout:.0f} s")
            index = bisect.bisect_right(self.stamps, sim_time) - 1
            return None if index < 0 else (self.stamps[index], *self.path[index], self.headings[index])

    def until(self, sim_time: float):
        """The path, headings and scan points recorded up to ``sim_time``, and the number of scans."""
        with self.arrived:
            end = bisect.bisect_right(self.stamps, sim_time)
            return self.path[:end], self.headings[:end], list(self.scan_points), self.scans

    def distance(self, sim_time: float = math.inf) -> float:
        path = numpy.asarray(self.until(sim_time)[0]).reshape(-1, 2)
        return float(numpy.hypot(*numpy.diff(path, axis=0).T).sum())


class Tour:
    """Drives the tour closed-loop on odometry, stepping the simulation between commands, and shows progress.

    Each command comes from the last odometry stamped at least half a control period before the time the
    simulation stopped at, so every run reads the same odometry and sends the same commands, however fast the
    machine and its messages are."""

    def __init__(self, sim: LockstepClient, recorder: Recorder, step_size: float, on_terminal: bool,
                 segment_sim_timeout: float = SEGMENT_SIM_TIMEOUT, sim_seconds: float = math.inf):
        self.sim = sim
        self.segment_sim_timeout = segment_sim_timeout
        self.sim_seconds = sim_seconds  # the tour ends there, wherever it is
        self.recorder = recorder
        self.control_steps = max(1, round(CONTROL_PERIOD / step_size))
        self.control_period = self.control_steps * step_size
        self.on_terminal = on_terminal
        self.publisher = sim.publisher("/cmd_vel", Twist)
        self.pose = None
        self.last_progress = 0.0

    def command(self, linear, angular):
        twist = Twist()
        twist.linear.x, twist.angular.z = linear, angular
        self.publisher.publish(twist)  # synchronous: the bridge applies it before the next step

    def advance(self):
        sim_time = self.sim.step(self.control_steps)
        self.pose = self.recorder.pose_at(sim_time - self.control_period / 2, timeout=STEP_WALL_TIMEOUT) or self.pose

    def progress(self, final=False):
        now = time.monotonic()
        if not final and now - self.last_progress < (PROGRESS_PERIOD if self.on_terminal else 4 * PROGRESS_PERIOD):
            return
        self.last_progress = now
        line = (f"  sim {self.pose[0]:6.1f} s | {self.recorder.distance():5.2f} m driven | "
                f"{self.recorder.scans:4d} scans")
        # On a terminal one line updates in place; in a log, a line every few seconds.
        if self.on_terminal:
            print("\r" + line, end="\n" if final else "", file=sys.stderr, flush=True)
        else:
            print(line, file=sys.stderr, flush=True)

    def wait(self, done, what):
        start = self.pose[0]
        wall_deadline = time.monotonic() + WALL_TIMEOUT
        while not done(self.pose) and self.pose[0] < self.sim_seconds:
            if self.pose[0] - start > self.segment_sim_timeout or time.monotonic() > wall_deadline:
                raise RuntimeError(f"the robot did not finish '{what}' (stuck at x {self.pose[1]:.2f}, "
                                   f"y {self.pose[2]:.2f})")
            self.progress()
            self.advance()

    def run(self):
        while self.pose is None:
            self.advance()
        heading = self.pose[3]
        for kind, amount in TOUR:
            if self.pose[0] >= self.sim_seconds:
                break
            _, x0, y0, _ = self.pose
            if kind == "forward":
                def forward(pose):
                    # Hold the heading the last turn ended on, so the legs come out straight.
                    self.command(LINEAR_SPEED, HEADING_GAIN * math.remainder(heading - pose[3], 2 * math.pi))
                    return math.hypot(pose[1] - x0, pose[2] - y0) >= amount
                self.wait(forward, f"forward {amount:.1f} m")
            else:
                heading += math.radians(amount)
                linear = LINEAR_SPEED / 3 if kind == "arc" else 0.0

                def turn(pose):
                    # Slow down towards the target heading: the wheels' ramp would carry a full-speed turn past it.
                    remaining = math.remainder(heading - pose[3], 2 * math.pi)
                    self.command(linear, max(MIN_TURN_SPEED, min(TURN_SPEED, HEADING_GAIN * remaining)))
                    return remaining < math.radians(1.0)
                self.wait(turn, f"{kind} {int(amount)} degrees")
        self.command(0.0, 0.0)
        self.progress(final=True)
