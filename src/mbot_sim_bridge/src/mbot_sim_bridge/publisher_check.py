"""A second publisher on a robot's ``joint_states``, reported once per node with what it sends and how to fix it.

The bridge publishes every moving joint of the robots it simulates. Gazebo tutorials (the mbot course among
them) also run ``joint_state_publisher``, which then publishes the same joints: zeros by default, or names
with empty positions when ``publish_default_positions`` is false. robot_state_publisher turns both into TF,
so the wheels' frames jump between the simulated angle and zero; messages without positions it drops, with
a warning every 300 s. Gazebo does nothing about it; the bridge says once which node it is, what it sends
and what to remove from the launch file.

``check_joint_state_publishers`` may be called on every pass of the node's loop: it looks at most once per
``CHECK_PERIOD_SECONDS`` of wall time and never blocks the caller, because the master query (~10 ms) runs in a
thread of its own, at most one at a time. A new foreign
publisher is sampled with a temporary subscriber, so the warning can say what it sends; the subscriber goes
away once every new publisher is classified (or after ``SAMPLE_SECONDS``).
"""
import threading
import time
from typing import Dict, Iterable, Set, Tuple

import rosgraph
import rospy
from sensor_msgs.msg import JointState

CHECK_PERIOD_SECONDS = 1.0
# How long a new publisher is listened to before the warning goes out without a sample of what it sends.
SAMPLE_SECONDS = 5.0


def check_joint_state_publishers(own_node_name: str, namespaces: Iterable[str]) -> None:
    """Look for other nodes publishing ``<namespace>/joint_states`` beside ``own_node_name``; warn once each.

    ``namespaces`` (the spawned robots' namespaces) is only iterated when a check is due, in the caller's thread,
    so a generator over the simulation's models costs nothing on the other calls.
    """
    _CHECK.start(own_node_name, namespaces)


def joint_states_topic(namespace: str) -> str:
    """Where a robot in ``namespace`` has its joint states, resolved as its publisher's name is (any text: a name
    rospy cannot resolve must not end the check)."""
    return rospy.resolve_name(rosgraph.names.ns_join(namespace or "/", "joint_states"))


def describe(message: JointState) -> str:
    """What a foreign joint_states message does to robot_state_publisher, in a few words."""
    names = ", ".join(message.name) or "no joints"
    if not message.position:
        return (f"joint names without positions ({names}), which robot_state_publisher drops "
                "with a warning every 300 s")
    what = "zero positions" if not any(message.position) else "positions"
    return (f"{what} for {names}, the same joints the simulator publishes, so robot_state_publisher's TF for them "
            "jumps between the two (in rviz the wheels flicker)")


def warning_text(topic: str, node: str, own_node_name: str, what: str) -> str:
    return (f"{topic} has a second publisher, node {node}, beside the simulator ({own_node_name}), which already "
            f"publishes every moving joint: {what}. Remove that node from the launch file that starts it (in the "
            "course's files, the <node name=\"joint_state_publisher\" .../> line); the simulator's joint states are "
            "all robot_state_publisher needs.")


class _PublisherCheck:
    def __init__(self):
        self._lock = threading.Lock()
        self._busy = False
        self._reported: Set[Tuple[str, str]] = set()
        # (topic, node) -> wall time it was first seen, for publishers whose first message is awaited
        self._pending: Dict[Tuple[str, str], float] = {}
        self._samplers: Dict[str, rospy.Subscriber] = {}
        self._own_node_name = ""
        self._next_check = 0.0

    def start(self, own_node_name: str, namespaces: Iterable[str]):
        now = time.monotonic()
        if now < self._next_check:
            return
        with self._lock:
            if self._busy:
                return
            self._busy = True
            self._own_node_name = own_node_name
        self._next_check = now + CHECK_PERIOD_SECONDS
        threading.Thread(target=self._check, args=(own_node_name, tuple(namespaces)), name="joint_states check",
                         daemon=True).start()

    def _check(self, own_node_name: str, namespaces: Tuple[str, ...]):
        try:
            self._check_once(own_node_name, namespaces)
        except Exception as error:  # whatever the names or the master do, the next call checks again
            rospy.logwarn_once(f"joint_states check: {type(error).__name__}: {error}; checking goes on")
        finally:
            with self._lock:
                self._busy = False

    def _check_once(self, own_node_name: str, namespaces: Tuple[str, ...]):
        try:
            publishers = dict(rosgraph.Master(own_node_name).getSystemState()[0])
        except Exception as error:  # the master gone or slow: the next call tries again
            rospy.logdebug(f"joint_states check: master query failed: {error}")
            return
        now = time.monotonic()
        with self._lock:
            for topic in {joint_states_topic(namespace) for namespace in namespaces}:
                nodes = publishers.get(topic, [])
                if own_node_name not in nodes:
                    continue  # the simulator publishes nothing there: another publisher is no conflict
                for node in nodes:
                    key = (topic, node)
                    if node != own_node_name and key not in self._reported and key not in self._pending:
                        self._pending[key] = now
                        if topic not in self._samplers:
                            self._samplers[topic] = rospy.Subscriber(topic, JointState, self._on_sample,
                                                                     callback_args=topic, queue_size=10)
            for key, first_seen in list(self._pending.items()):
                if now - first_seen > SAMPLE_SECONDS:
                    self._report(key, f"no message from it arrived within {SAMPLE_SECONDS:.0f} s")
            self._drop_idle_samplers()

    def _on_sample(self, message: JointState, topic: str):
        key = (topic, message._connection_header.get("callerid", ""))
        with self._lock:
            if key in self._pending:
                self._report(key, f"it sends {describe(message)}")
                self._drop_idle_samplers()

    def _report(self, key: Tuple[str, str], what: str):
        del self._pending[key]
        self._reported.add(key)
        rospy.logwarn(warning_text(key[0], key[1], self._own_node_name, what))

    def _drop_idle_samplers(self):
        waiting = {topic for topic, _ in self._pending}
        for topic in [topic for topic in self._samplers if topic not in waiting]:
            self._samplers.pop(topic).unregister()


_CHECK = _PublisherCheck()
