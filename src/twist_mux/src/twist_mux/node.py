"""The ``twist_mux`` node: ``~topics`` and ``~locks`` (lists of name, topic, timeout, priority), the selected
input's Twist on ``cmd_vel_out``, upstream's diagnostics on /diagnostics every second."""
import threading

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool

from .mux import HUGE_VALUE, TwistMux, check_topics, huge_field, non_finite_field, parse_handles

DIAGNOSTICS_PERIOD = 1.0
# How often a lock that engaged by timing out (its publisher gone) is looked for; a Bool engages it at once.
LOCK_CHECK_PERIOD = 0.05


class TwistMuxNode:
    def __init__(self):
        inputs, input_errors = parse_handles("velocity", rospy.get_param("~topics", None),
                                             rospy.resolve_name("~topics"))
        locks, lock_errors = parse_handles("lock", rospy.get_param("~locks", None), rospy.resolve_name("~locks"))
        inputs, locks, topic_errors = check_topics(inputs, locks, rospy.resolve_name("cmd_vel_out"),
                                                   rospy.resolve_name)
        for error in input_errors + lock_errors + topic_errors:
            rospy.logerr(error)
        if not inputs:
            rospy.logwarn(f"{rospy.resolve_name('~topics')}: no input topics; nothing will be published on "
                          f"{rospy.resolve_name('cmd_vel_out')}")
        self.mux = TwistMux(inputs, locks)
        self._lock = threading.Lock()
        self._warned = set()
        self.publisher = rospy.Publisher("cmd_vel_out", Twist, queue_size=1)
        self.diagnostics = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=1)
        self._status_name = rospy.get_name().lstrip("/") + ": Twist mux status"
        for handle in inputs:
            rospy.loginfo(self._describe("Topic", handle))
            rospy.Subscriber(handle.topic, Twist, self._on_twist, handle, queue_size=1)
        for lock in locks:
            rospy.loginfo(self._describe("Lock", lock))
            rospy.Subscriber(lock.topic, Bool, self._on_lock, lock, queue_size=1)
        rospy.Timer(rospy.Duration(LOCK_CHECK_PERIOD), self._check_locks)
        rospy.Timer(rospy.Duration(DIAGNOSTICS_PERIOD), self._publish_diagnostics)

    @staticmethod
    def _describe(kind, handle) -> str:
        timeout = f"{handle.timeout:f}s" if handle.timeout else "None"
        return (f"{kind} handler '{handle.name}' subscribed to topic '{rospy.resolve_name(handle.topic)}': "
                f"timeout = {timeout}, priority = {handle.priority}")

    def _warn_once(self, key, text: str):
        if key not in self._warned:
            self._warned.add(key)
            rospy.logwarn(text)

    def _on_twist(self, message: Twist, handle):
        values = (message.linear.x, message.linear.y, message.linear.z,
                  message.angular.x, message.angular.y, message.angular.z)
        bad = non_finite_field(values)
        if bad is not None:
            # Upstream forwards anything; a NaN reaching a base controller is refused there at best.
            self._warn_once(("non-finite", handle.name), f"twist_mux: input '{handle.name}' "
                            f"({rospy.resolve_name(handle.topic)}): {bad[0]} is {bad[1]}; such messages are "
                            "dropped (said once per input)")
            return
        huge = huge_field(values)
        if huge is not None:
            self._warn_once(("huge", handle.name), f"twist_mux: input '{handle.name}' "
                            f"({rospy.resolve_name(handle.topic)}): {huge[0]} is {huge[1]:g}, beyond {HUGE_VALUE:g}; "
                            "forwarded as upstream does, the base's limits apply (said once per input)")
        with self._lock:
            if self.mux.on_twist(handle, rospy.get_time()):
                self.publisher.publish(message)

    def _on_lock(self, message: Bool, lock):
        with self._lock:
            self.mux.on_lock(lock, message.data, rospy.get_time())
            self._stop_if_due()

    def _check_locks(self, _event):
        with self._lock:
            self._stop_if_due()

    def _stop_if_due(self):
        if self.mux.stop_due(rospy.get_time()):
            self.publisher.publish(Twist())

    def _publish_diagnostics(self, _event):
        with self._lock:
            values = self.mux.status(rospy.get_time())
        status = DiagnosticStatus(level=DiagnosticStatus.OK, name=self._status_name, message="ok",
                                  hardware_id="none", values=[KeyValue(key, value) for key, value in values])
        array = DiagnosticArray(status=[status])
        array.header.stamp = rospy.Time.now()
        self.diagnostics.publish(array)


def main():
    rospy.init_node("twist_mux")
    TwistMuxNode()
    rospy.spin()
