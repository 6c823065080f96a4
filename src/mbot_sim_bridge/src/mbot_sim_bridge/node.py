"""The ``gazebo`` node: one loop that owns the PyBullet engine, steps it, runs plugin updates, publishes /clock.

Everything that touches the engine runs in the loop's thread; ROS callbacks (services, cmd_vel) only hand
work or values over. The loop paces itself with time.monotonic() to follow the real-time factor: it must not
use rospy.Rate or rospy.sleep, because under use_sim_time those wait for the /clock this loop publishes.
"""
import math
import os
import queue
import sys
import threading
import time
from concurrent.futures import Future, TimeoutError as FutureTimeout
from typing import Callable, Optional

import pybullet
import rospkg
import rospy
import rospy.impl.simtime
from rosgraph_msgs.msg import Clock

from .core.added_plugins import ADDED_JOINT_STATE_RATE
from .core.clock import UpdateTimer
from .core.errors import BridgeError, WorldError
from .gazebo_paths import model_path
from .core.description.sdf_world import parse_world
from .core.simulation import MAX_BATCH_SIM_SECONDS, Simulation
from .core.xml_values import parse_bool
from . import loop_publishing
from .plugins import loop_publisher, ros_time
from .publisher_check import check_joint_state_publishers
from .package_uris import resolve_package_uris
from .processes import end_start_up, init_node, stop_on_signals
from .plugins.registry import REGISTRY
from .ros_parameters import RosParameters
from .services import GazeboRosApi

DEFAULT_CLOCK_FREQUENCY = 100.0
# How far ahead of the wall clock the loop may run before it sleeps, at a real-time factor > 0.
_PACING_SLACK_SECONDS = 0.002


class LoopBusy(BridgeError):
    """A request the loop did not take within its time: refused, and never carried out."""


def _bool_param(name: str, default: bool) -> bool:
    value = rospy.get_param(name, default)
    if isinstance(value, bool):
        return value
    try:
        return parse_bool(str(value))
    except ValueError as error:
        raise BridgeError(f"parameter {rospy.resolve_name(name)}: {error}, got '{value}'") from None


def _rate_param(name: str, default: float) -> float:
    """A rate in Hz of sim time (≤ 0: every step): a finite number, else the node stops naming the parameter (a
    NaN here used to reach every robot's spawn as a bad <updateRate> of a plugin the user never wrote)."""
    value = rospy.get_param(name, default)
    try:
        rate = float(value)
    except (TypeError, ValueError):
        rate = math.nan
    if isinstance(value, bool) or not math.isfinite(rate):
        raise BridgeError(f"parameter {rospy.resolve_name(name)}: not a finite rate in Hz, got '{value}'")
    return rate


class SimBridgeNode:
    def __init__(self):
        # First: the writer process starts while the world loads, and every loop publisher writes through it.
        self.publishing = loop_publishing.start()
        # Every ~param is read here, once (teleop_twist_keyboard style), and logged once below.
        self.world_path = rospy.get_param("~world_name", "") or os.path.join(_workspace_worlds(), "empty.world")
        paused = _bool_param("~paused", False)
        # Lockstep: start paused; the simulation advances only through ~step_simulation.
        lockstep = _bool_param("~lockstep", False)
        requested_gui = _bool_param("~gui", False)
        headless = _bool_param("~headless", False)
        real_time_factor = str(rospy.get_param("~real_time_factor", "")).strip()
        # Gazebo publishes /clock on every step; from Python that costs more than the step itself, so the
        # bridge defaults to 100 Hz and also publishes right before any plugin output (see README).
        clock_frequency = _rate_param("~pub_clock_frequency", DEFAULT_CLOCK_FREQUENCY)
        joint_state_rate = _rate_param("~joint_state_rate", ADDED_JOINT_STATE_RATE)
        seed = int(rospy.get_param("~seed", 0))

        world = parse_world(self.world_path, model_path())
        gui = requested_gui and not headless and bool(os.environ.get("DISPLAY"))
        if requested_gui and not gui:
            why = "headless:=true" if headless else "no DISPLAY is set"
            rospy.loginfo(f"gui:=true, but {why}: running without a window")
        self.sim = Simulation(world, REGISTRY, seed, pybullet.GUI if gui else pybullet.DIRECT, joint_state_rate,
                              RosParameters(), resolve_package_uris)
        self.sim.paused = paused or lockstep
        self.sim.call_in_loop = self.call_in_loop
        physics = world.physics
        self._real_time_factor_param = float(real_time_factor) if real_time_factor else None
        self.physics_changed()

        self.clock_publisher = loop_publisher("/clock", Clock)
        self.clock_timer = UpdateTimer(clock_frequency)
        self._requests: "queue.Queue[tuple]" = queue.Queue()
        self.steps_left = 0  # of the step_simulation under way
        self._stop = threading.Event()  # set by run(): a stop asked for while a step request runs
        self._pace_wall_start = self._pace_sim_start = 0.0
        self._last_clock = -1.0
        # gazebo_ros sets /use_sim_time only when nobody has.
        if not rospy.has_param("/use_sim_time"):
            rospy.set_param("/use_sim_time", True)
        self._sets_rospy_time = _take_over_rospy_clock()
        clock = "every step" if clock_frequency <= 0 else f"at {clock_frequency:.0f} Hz"
        state = "lockstep" if lockstep else "paused" if paused else "running"
        rospy.loginfo(f"world {self.world_path}: step {physics.max_step_size:.4f} s, gravity {physics.gravity}, "
                      f"real-time factor {self.real_time_factor or '0 (as fast as possible)'}, /clock {clock}, "
                      f"{state}, {'GUI' if gui else 'headless'}")
        # Last: its services take calls at once, from other threads, and those use everything above.
        self.api = GazeboRosApi(self)

    # -- called from ROS threads -------------------------------------------------------------------------
    def call_in_loop(self, function: Callable, timeout: Optional[float] = 30.0):
        """Run ``function`` in the loop's thread (the only one that touches the engine) and return its result.
        The loop takes requests between its batches of steps, during a step_simulation too; one it has not taken
        within ``timeout`` (a spawn of its own can take that long) is withdrawn and refused with LoopBusy, so a
        call never fails and is carried out all the same."""
        future: Future = Future()
        self._requests.put((function, future))
        try:
            return future.result(timeout)
        except FutureTimeout:
            if future.cancel():
                raise LoopBusy(f"the simulator did not take the request within {timeout:g} s (its loop was busy with "
                               "another request); it was not carried out") from None
            return future.result()  # taken meanwhile: answered once carried out

    # -- loop thread --------------------------------------------------------------------------------------
    def set_paused(self, paused: bool):
        self.sim.paused = paused
        self._restart_pacing()

    def reset(self, simulation: bool):
        """reset_simulation (sim time back to 0) or reset_world (models only); plugins are reset either way."""
        self.sim.reset(simulation)
        if simulation:
            self.clock_timer.reset(0.0)
            self._last_clock = -1.0
        self._restart_pacing()

    def step(self, count: int):
        """Exactly ``count`` physics steps, outputs and /clock included (lockstep); /clock ends at the last step,
        so the nodes' ROS time is the sim time the answer reports. Other requests are served between the
        batches, so a long step holds up no call."""
        self.steps_left = count
        try:
            while self.steps_left > 0 and not self._stop.is_set():  # Ctrl-C ends a long request too
                self.steps_left -= self.sim.advance(self.steps_left, self._before_updates)
                self.publishing.flush(wait=True)
                self._serve_requests(block=False)
        finally:
            self.steps_left = 0
        if self._last_clock < self.sim.sim_time:
            self._publish_clock(self.sim.sim_time)
        self.publishing.sync()
        self._restart_pacing()

    def run(self, stop: threading.Event):
        self._stop = stop
        self._restart_pacing()
        while not (stop.is_set() or rospy.is_shutdown()):
            self._serve_requests(block=self.sim.paused)
            if self.sim.paused:
                self.publishing.flush()
                continue
            until_clock = self.clock_timer.steps_until_due(self.sim.sim_time, self.step_size)
            self.sim.advance(min(until_clock, self._batch_steps), self._before_updates)
            self.publishing.flush(wait=True)
            check_joint_state_publishers(rospy.get_name(), (model.namespace for model in self.sim.models.values()))
            self._pace()

    def _before_updates(self, now: float, plugins_due: bool):
        # /clock goes first, so no message is stamped ahead of the clock its subscribers have seen.
        if self.clock_timer.due(now) or plugins_due:
            self._publish_clock(now)

    def _publish_clock(self, now: float):
        stamp = ros_time(now)
        self.clock_publisher.publish(Clock(clock=stamp))
        if self._sets_rospy_time:
            rospy.rostime._set_rostime(stamp)
        self.api.model_states.publish()
        self.api.link_states.publish()
        self.api.performance_metrics.publish()
        # The timer guarantees the longest gap between two /clock messages, counted from the last one.
        self.clock_timer.reset(now)
        self._last_clock = now

    def _serve_requests(self, block: bool):
        try:
            function, future = self._requests.get(timeout=0.1) if block else self._requests.get_nowait()
        except queue.Empty:
            return
        while True:
            if future.set_running_or_notify_cancel():
                try:
                    future.set_result(function())
                except Exception as error:  # handed back to the waiting ROS thread, which reports it
                    future.set_exception(error)
            try:
                function, future = self._requests.get_nowait()
            except queue.Empty:
                return

    def physics_changed(self):
        """The step size and pacing from the simulation's physics (at start and after set_physics_properties): the
        real-time factor is step × update rate, as Gazebo's, unless ~real_time_factor sets it."""
        physics = self.sim.engine.physics
        self.step_size = physics.max_step_size
        self.real_time_factor = (self._real_time_factor_param if self._real_time_factor_param is not None
                                 else physics.max_step_size * physics.real_time_update_rate)
        self._batch_steps = max(1, int(round(MAX_BATCH_SIM_SECONDS / self.step_size)))
        self._restart_pacing()

    def _restart_pacing(self):
        self._pace_wall_start = time.monotonic()
        self._pace_sim_start = self.sim.sim_time

    def _pace(self):
        if self.real_time_factor <= 0:
            return
        target = self._pace_wall_start + (self.sim.sim_time - self._pace_sim_start) / self.real_time_factor
        ahead = target - time.monotonic()
        if ahead > _PACING_SLACK_SECONDS:
            self.publishing.flush()
            time.sleep(ahead)

    def close(self):
        self.sim.close()
        loop_publishing.stop()


def _take_over_rospy_clock() -> bool:
    """Under use_sim_time rospy subscribes every node to /clock, this one too: each tick the loop published came
    back over TCP to a reader thread that took the GIL from the loop (a fifth of a core at 10x real time).
    Instead the loop sets rospy's time as it publishes; True when it must (rospy's simtime has no public switch)."""
    subscriber = getattr(rospy.impl.simtime, "_clock_sub", None)
    if subscriber is None:
        return False
    subscriber.unregister()
    rospy.impl.simtime._clock_sub = None
    return True


def _workspace_worlds() -> str:
    """The workspace's worlds/ folder, reached as $(find mbot_gazebo)/worlds like Gazebo launch files do."""
    try:
        return os.path.join(rospkg.RosPack().get_path("mbot_gazebo"), "worlds")
    except rospkg.ResourceNotFound:
        raise WorldError("no world_name given and package mbot_gazebo (which holds worlds/empty.world) is not "
                         "on ROS_PACKAGE_PATH; source devel/setup.bash") from None


def main():
    # rospy's own SIGINT handler shuts the node down inside the signal, in whatever the main thread was doing;
    # when that is a publish or a call to the master, it waits on a lock the main thread holds, for ever.
    # Here a signal only asks the loop to stop, and the shutdown runs after it, outside any lock.
    stop = stop_on_signals()
    # Running flat out, the loop thread holds the GIL between steps; every hand-off to a ROS thread (a subscriber
    # connecting, a service call, cmd_vel) then waits out the switch interval, and a connection takes dozens of
    # them: at the default 5 ms a new subscriber at real_time_factor 0 waited up to half a second (bench).
    sys.setswitchinterval(0.001)
    verbose = "--verbose" in rospy.myargv(sys.argv)[1:]
    init_node("gazebo", log_level=rospy.DEBUG if verbose else rospy.INFO, disable_signals=True)
    # A shutdown rospy starts from outside: the master's request when another node registers as /gazebo.
    requested = []
    rospy.core.add_preshutdown_hook(lambda reason: (requested.append(reason), stop.set()))
    try:
        node = SimBridgeNode()
    except BridgeError as error:
        rospy.logfatal(str(error))
        rospy.signal_shutdown("bad input")
        sys.exit(1)
    end_start_up()
    try:
        node.run(stop)
        if requested:
            # One line, and exit status 0, as a rospy node that rospy.spin() returns from on that request.
            rospy.logwarn(f"the simulator stops: {requested[0]}")
    except loop_publishing.WriterStopped as error:
        rospy.logfatal(str(error))
        sys.exit(1)
    finally:
        node.close()
        rospy.signal_shutdown("stopped")
