"""``spawner [options] CONTROLLER ...``: loads controllers, starts them, and stops and unloads them on exit.

Upstream's command line (ros_control 0.20): ``--stopped``, ``--wait-for TOPIC``, ``--namespace NS``,
``--timeout T`` (default 30 s; <= 0 waits for ever), ``--no-timeout``, ``--shutdown-timeout`` (accepted,
no effect, with upstream's deprecation warning). An argument naming an existing YAML file loads that file
onto the parameter server and spawns the controllers it defines.

Unlike upstream, SIGINT/SIGTERM only ask the main thread to finish: the controllers are then stopped and
unloaded while the node can still call services, rather than from rospy's shutdown hook.
"""
import argparse
import os
import sys
import threading
import time

import rosparam
import rospy
import rospy.impl.simtime
import yaml
from controller_manager_msgs.srv import LoadController, SwitchController, SwitchControllerRequest, UnloadController
from std_msgs.msg import Bool

from mbot_sim_bridge.processes import init_node, stop_on_signals

_POLL_SECONDS = 0.5


def parse_args(args=None):
    parser = argparse.ArgumentParser(description="Controller spawner")
    parser.add_argument("--stopped", action="store_true", help="loads controllers, but does not start them")
    parser.add_argument("--wait-for", metavar="topic",
                        help='does not load or start controllers until it hears "True" on a topic (Bool)')
    parser.add_argument("--namespace", metavar="ns", help="namespace of the controller_manager services")
    parser.add_argument("--timeout", metavar="T", type=float, default=30,
                        help="how long to wait for controller_manager services when starting up [s] "
                             "(default: 30). <=0 waits indefinitely.")
    parser.add_argument("--no-timeout", action="store_true",
                        help="wait for controller_manager services indefinitely (same as `--timeout 0`)")
    parser.add_argument("--shutdown-timeout", help="DEPRECATED: this argument has no effect.")
    parser.add_argument("controllers", metavar="controller", nargs="+", help="controllers to load")
    return parser.parse_args(args=args)


class Spawner:
    def __init__(self, args, stop: threading.Event):
        self.args = args
        self.stop = stop
        namespace = args.namespace or ""
        if namespace and not namespace.endswith("/"):
            namespace += "/"
        self.services = {kind: namespace + "controller_manager/" + kind
                         for kind in ("load_controller", "switch_controller", "unload_controller")}
        self.timeout = None if args.no_timeout or args.timeout <= 0 else args.timeout
        self.loaded = []

    def wait_for_services(self) -> bool:
        """Upstream's wait: each service in turn; past the timeout, wait on only while sim time has not started."""
        for name in self.services.values():
            rospy.loginfo("Controller Spawner: Waiting for service " + name)
            started = time.monotonic()
            while not self.stop.is_set():
                try:
                    rospy.wait_for_service(name, timeout=_POLL_SECONDS)
                    break
                except rospy.ROSException:
                    if self.timeout is None or time.monotonic() - started < self.timeout:
                        continue
                    if rospy.get_param("/use_sim_time", False) and rospy.get_rostime() == rospy.Time(0):
                        rospy.loginfo("Waiting for /clock to be available...")
                        started = time.monotonic()
                        continue
                    rospy.logwarn("Controller Spawner couldn't find the expected controller_manager ROS interface.")
                    return False
        return not self.stop.is_set()

    def wait_for_topic(self) -> bool:
        heard = []
        subscriber = rospy.Subscriber(self.args.wait_for, Bool, lambda message: heard.append(message.data))
        started, warned = time.monotonic(), False
        while not (heard and heard[-1]):
            if self.stop.wait(0.01):
                return False
            if not heard and not warned and self.timeout is not None and time.monotonic() - started > self.timeout:
                warned = True
                rospy.logwarn('Controller Spawner hasn\'t heard anything from its "wait for" '
                              f'topic ({self.args.wait_for})')
        subscriber.unregister()
        return True

    def controller_names(self):
        names = []
        for name in self.args.controllers:
            if os.path.exists(name):
                # A YAML file: its top-level keys are the controllers, loaded in the spawner's namespace.
                with open(name) as stream:
                    document = yaml.safe_load(stream) or {}
                rosparam.upload_params(rospy.get_namespace(), document)
                names.extend(document)
            else:
                names.append(name)
        return names

    def run(self) -> int:
        if not self.wait_for_services():
            return 1
        if self.args.wait_for and not self.wait_for_topic():
            return 0
        load = rospy.ServiceProxy(self.services["load_controller"], LoadController)
        for name in self.controller_names():
            rospy.loginfo("Loading controller: " + name)
            if load(name).ok:
                self.loaded.append(name)
            else:
                rospy.logerr(f"Failed to load {name}")
        rospy.loginfo(f"Controller Spawner: Loaded controllers: {', '.join(self.loaded)}")
        if self.stop.is_set():
            return 0
        if not self.args.stopped and self.loaded:
            switch = rospy.ServiceProxy(self.services["switch_controller"], SwitchController)
            if switch(self.loaded, [], SwitchControllerRequest.STRICT, False, 0.0).ok:
                rospy.loginfo(f"Started controllers: {', '.join(self.loaded)}")
            else:
                rospy.logerr(f"Failed to start controllers: {', '.join(self.loaded)}")
        _stop_following_sim_time()
        self.stop.wait()
        return 0

    def shutdown(self):
        """Stop every controller this spawner loaded, then unload them in reverse order."""
        if not self.loaded:
            return
        rospy.loginfo("Shutting down spawner. Stopping and unloading controllers...")
        try:
            rospy.loginfo("Stopping all controllers...")
            rospy.ServiceProxy(self.services["switch_controller"], SwitchController)(
                [], self.loaded, SwitchControllerRequest.STRICT, False, 0.0)
            rospy.loginfo("Unloading all loaded controllers...")
            unload = rospy.ServiceProxy(self.services["unload_controller"], UnloadController)
            for name in reversed(self.loaded):
                rospy.loginfo(f"Trying to unload {name}")
                unload(name)
                rospy.loginfo(f"Succeeded in unloading {name}")
        except (rospy.ServiceException, rospy.ROSException) as error:
            rospy.logwarn(f"Controller Spawner error while taking down controllers: {error}")


def _stop_following_sim_time():
    """From here the spawner only waits for its end. Under /use_sim_time rospy takes in every /clock message
    (thousands a wall second while the simulation runs fast), CPU the simulator needs on a small machine (5 ms
    per sim second on two cores); rospy has no call to stop that, so its /clock subscriber is unregistered. The
    spawner's log lines at shutdown then carry the last sim time it had."""
    subscriber = getattr(rospy.impl.simtime, "_clock_sub", None)  # set only under /use_sim_time
    if subscriber is not None:
        subscriber.unregister()


def main():
    args = parse_args(rospy.myargv()[1:])
    stop = stop_on_signals()
    init_node("spawner", anonymous=True, disable_signals=True)
    if args.shutdown_timeout is not None:
        rospy.logwarn("DEPRECATION warning: --shutdown-timeout has no effect.")
    spawner = Spawner(args, stop)
    try:
        status = spawner.run()
    finally:
        spawner.shutdown()
        rospy.signal_shutdown("spawner done")
    sys.exit(status)
