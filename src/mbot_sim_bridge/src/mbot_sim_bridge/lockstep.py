"""A test's handle on a bridge running in lockstep (``lockstep:=true``): command, step, read.

    from mbot_sim_bridge.lockstep import LockstepClient
    sim = LockstepClient()                              # waits for /gazebo/step_simulation
    cmd_vel = sim.publisher("/cmd_vel", Twist)          # synchronous; waits until the bridge subscribes
    odom = sim.recorder(["/odom"])                      # raw bytes per (topic, publisher), in arrival order
    sim.subscriber("/scan", LaserScan, on_scan)         # or decoded messages to a callback
    cmd_vel.publish(Twist(linear=Vector3(x=0.2)))
    sim.step(500)                                       # the command is applied before the first step
    sim.settle()                                        # every message of those steps has been received
    odom.messages("/odom", "/gazebo")[-1]

The bridge applies what reached it before a step request first (see ``subscriptions``); publishers made here
are synchronous, so a ``publish`` has reached the bridge by the time it returns.
"""
import threading
import time
import warnings
from collections import defaultdict
from typing import Dict, List, Tuple
from xmlrpc.client import ServerProxy

import rosgraph
import rospy
from mbot_sim_msgs.srv import StepSimulation

from .subscriptions import TrackedSubscriber, drain


class Recorder:
    """The serialized messages of some topics, per (topic, publishing node), in the order they arrived."""

    def __init__(self, topics: List[str]):
        self._lock = threading.Lock()
        self._messages: Dict[Tuple[str, str], List[bytes]] = defaultdict(list)
        self.subscribers = [TrackedSubscriber(topic, rospy.AnyMsg, self._receiver(topic), queue_size=None)
                            for topic in topics]

    def _receiver(self, topic):
        def receive(message):
            with self._lock:
                self._messages[(topic, message._connection_header["callerid"])].append(bytes(message._buff))
        return receive

    def messages(self, topic: str = None, publisher: str = None) -> Dict[Tuple[str, str], List[bytes]]:
        """A copy of what arrived, optionally only one topic and/or publishing node."""
        with self._lock:
            return {key: list(values) for key, values in self._messages.items()
                    if (topic is None or key[0] == topic) and (publisher is None or key[1] == publisher)}

    def clear(self):
        with self._lock:
            self._messages.clear()

    def close(self):
        for subscriber in self.subscribers:
            subscriber.unregister()


def _publishers_sending(topic: str) -> int:
    """How many of ``topic``'s publishers list an outbound connection to this node (their getBusInfo)."""
    me = rospy.get_caller_id()
    master = rosgraph.Master(me)
    publishers = next((nodes for name, nodes in master.getSystemState()[0] if name == topic), [])
    sending = 0
    for node in publishers:
        try:
            code, _, connections = ServerProxy(master.lookupNode(node)).getBusInfo(me)
        except (OSError, rosgraph.MasterError):
            continue  # gone, or not yet registered: counted on a later look
        sending += code == 1 and any(info[1] == me and info[2] == "o" and info[4] == topic for info in connections)
    return sending


class LockstepClient:
    def __init__(self, gazebo_namespace: str = "/gazebo", timeout: float = 60.0):
        self.timeout = timeout
        service = gazebo_namespace + "/step_simulation"
        rospy.wait_for_service(service, timeout=timeout)
        self._step = rospy.ServiceProxy(service, StepSimulation, persistent=True)
        self._recorders: List[Recorder] = []

    def publisher(self, topic: str, message_type, subscribers: int = 1) -> rospy.Publisher:
        """A synchronous publisher, returned once ``subscribers`` nodes (the bridge) are connected to it."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SyntaxWarning)  # rospy's note about queue_size=None: chosen here
            publisher = rospy.Publisher(topic, message_type, queue_size=None)
        self._wait(lambda: publisher.get_num_connections() >= subscribers, f"{topic} to be subscribed")
        return publisher

    def recorder(self, topics: List[str], publishers: Dict[str, int] = None) -> Recorder:
        """Start recording ``topics``; returns once each has its number of ``publishers`` (default 1) connected."""
        recorder = Recorder(topics)
        for topic, subscriber in zip(topics, recorder.subscribers):
            self._wait_connected(subscriber, topic, (publishers or {}).get(topic, 1))
        self._recorders.append(recorder)
        return recorder

    def subscriber(self, topic: str, message_type, callback, publishers: int = 1) -> TrackedSubscriber:
        """A subscriber whose ``callback`` gets every message from the next step on: returned once ``publishers``
        nodes are connected to it and count this node."""
        subscriber = TrackedSubscriber(topic, message_type, callback, queue_size=None)
        self._wait_connected(subscriber, topic, publishers)
        return subscriber

    def step(self, steps: int) -> float:
        """Advance exactly ``steps`` physics steps; returns the sim time after them."""
        response = self._step(steps)
        if not response.success:
            raise RuntimeError(response.status_message)
        return response.sim_time

    def settle(self):
        """Wait until every recorder has handled all the bridge sent before now."""
        if not drain([s for recorder in self._recorders for s in recorder.subscribers], timeout=self.timeout):
            raise RuntimeError(f"recorded topics still busy after {self.timeout:.0f} s")

    def close(self):
        for recorder in self._recorders:
            recorder.close()
        self._step.close()

    def _wait_connected(self, subscriber: TrackedSubscriber, topic: str, wanted: int):
        self._wait(lambda: subscriber.subscriber.get_num_connections() >= wanted,
                   f"{topic} to have {wanted} publishers")
        # This side counts a connection as soon as it has one; a publisher counts it a little later, and the
        # bridge skips publishing to nobody. Under load that gap swallowed a run's first messages.
        self._wait(lambda: _publishers_sending(topic) >= wanted, f"{topic}'s publishers to count this node")

    def _wait(self, condition, what: str):
        deadline = time.monotonic() + self.timeout
        while not condition():
            if time.monotonic() > deadline:
                raise RuntimeError(f"timed out after {self.timeout:.0f} s waiting for {what}")
            time.sleep(0.01)
