#!/usr/bin/env python3
"""twist_mux against upstream's system scenarios (no input: no output; one input passes; a higher priority
overrides and the lower one resumes when it times out), then the locks (strictly-below masking, a heartbeat
lock that times out, the zero Twist when a lock engages), NaN, inf and huge values, and the diagnostics. Then, in
this node on the same launch (rostest starts the launch again for each <test>), joystick_relay.py
(test_joystick_relay.py) and the twist marker server (test_marker_server.py)."""
import math
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Log
from std_msgs.msg import Bool

from sim_support import init_test_node, twist, wait_for
from test_joystick_relay import JoystickRelay
from test_marker_server import MarkerServer

# The configuration's longest input timeout (input1), and a margin for the messages in flight.
LONGEST_INPUT_TIMEOUT = 0.7
SETTLE = 0.3


class RatePublishers:
    """Each topic's message repeated at its rate from one thread (what upstream's rate_publishers does)."""

    def __init__(self, topics):
        self.publishers = {topic: rospy.Publisher(topic, kind, queue_size=10) for topic, kind in topics.items()}
        self.plan = {}
        self.lock = threading.Lock()
        threading.Thread(target=self._run, daemon=True).start()

    def pub(self, topic, message, rate=None):
        with self.lock:
            self.publishers[topic].publish(message)
            self.plan[topic] = (message, 1.0 / rate, time.monotonic()) if rate else None

    def stop(self, topic):
        with self.lock:
            self.plan[topic] = None

    def _run(self):
        while not rospy.is_shutdown():
            with self.lock:
                now = time.monotonic()
                for topic, planned in self.plan.items():
                    if planned is not None and now - planned[2] >= planned[1]:
                        self.publishers[topic].publish(planned[0])
                        self.plan[topic] = (planned[0], planned[1], now)
            time.sleep(0.005)


class TwistMuxSystem(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        init_test_node("twist_mux_system_test")
        cls.received = []
        cls.warnings = []
        cls.diagnostics = []
        rospy.Subscriber("cmd_vel_out", Twist, lambda message: cls.received.append((time.monotonic(), message)))
        rospy.Subscriber("/rosout", Log, lambda log: cls.warnings.append(log.msg) if log.level >= Log.WARN else None)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.diagnostics.append)
        cls.rates = RatePublishers({"vel_1": Twist, "vel_2": Twist, "vel_3": Twist, "lock_1": Bool, "lock_2": Bool})
        # Upstream's test launch keeps lock_1 (priority 255, timeout 0.5 s) alive with false at 20 Hz.
        cls.rates.pub("lock_1", Bool(False), rate=20)
        for topic in ("vel_1", "vel_2", "vel_3", "lock_1", "lock_2"):
            wait_for(lambda: cls.rates.publishers[topic].get_num_connections() > 0,
                     what=f"twist_mux to subscribe {topic}")

    def setUp(self):
        """As upstream's tearDown: the inputs quiet and the locks free, past the longest input timeout."""
        for topic in ("vel_1", "vel_3"):
            self.rates.stop(topic)
        self.rates.pub("lock_2", Bool(False))
        self.rates.pub("lock_1", Bool(False), rate=20)
        time.sleep(LONGEST_INPUT_TIMEOUT + SETTLE)  # the inputs must expire: nothing to wait on but time
        self.mark = time.monotonic()

    def since_mark(self):
        return [message for stamp, message in self.received if stamp > self.mark]

    def wait_output(self, expected, what):
        def latest_is_expected():
            latest = self.since_mark()
            return latest and latest[-1] == expected
        wait_for(latest_is_expected, what=what)
        self.mark = time.monotonic()

    def test_empty(self):
        time.sleep(SETTLE)
        self.assertEqual(self.since_mark(), [], "twist_mux should not be publishing without any input")

    def test_basic(self):
        self.rates.pub("vel_1", twist(2.0), rate=5)
        self.wait_output(twist(2.0), "input1's twist on cmd_vel_out")

    def test_basic_with_priorities(self):
        self.rates.pub("vel_1", twist(2.0), rate=5)
        self.wait_output(twist(2.0), "input1 alone to pass")
        self.rates.pub("vel_3", twist(0.0, 1.0), rate=10)
        self.wait_output(twist(0.0, 1.0), "input3 (priority 10) to override input1 (priority 5)")
        self.rates.stop("vel_3")
        self.wait_output(twist(2.0), "input1 to pass again once input3 timed out (0.3 s)")

    def test_lock_masks_lower_priorities_only(self):
        self.rates.pub("vel_1", twist(2.0), rate=10)
        self.wait_output(twist(2.0), "input1 to pass")
        self.rates.pub("lock_2", Bool(True))
        # The lock (priority 10) silences input1 (5) with one zero Twist...
        self.wait_output(Twist(), "the zero Twist when emergency_10 engages")
        time.sleep(SETTLE)
        self.assertEqual(self.since_mark(), [], "input1 passed under a lock of higher priority")
        # ...but not input3, whose priority equals the lock's (upstream masks only priorities below a lock's).
        self.rates.pub("vel_3", twist(0.5), rate=10)
        self.wait_output(twist(0.5), "input3 to pass under the lock of its own priority")
        self.rates.stop("vel_3")
        self.rates.pub("lock_2", Bool(False))
        self.wait_output(twist(2.0), "input1 to pass once the lock is released and input3 timed out")

    def test_heartbeat_lock_that_times_out_stops_everything(self):
        self.rates.pub("vel_3", twist(1.0), rate=10)
        self.wait_output(twist(1.0), "input3 to pass")
        self.rates.stop("lock_1")  # its publisher gone: after 0.5 s emergency_255 locks
        self.wait_output(Twist(), "the zero Twist when emergency_255 times out")
        time.sleep(SETTLE)
        self.assertEqual(self.since_mark(), [], "an input passed while the 255 lock had timed out")
        self.rates.pub("lock_1", Bool(False), rate=20)
        self.wait_output(twist(1.0), "input3 to pass once the heartbeat is back")

    def test_non_finite_and_huge_values(self):
        self.rates.pub("vel_3", twist(1.0), rate=20)
        self.wait_output(twist(1.0), "input3 to pass")
        for bad in (math.nan, math.inf, -math.inf):
            self.rates.pub("vel_3", twist(bad), rate=20)
            time.sleep(0.1)
        self.assertFalse(any(not math.isfinite(message.linear.x) for message in self.since_mark()),
                         "a non-finite Twist passed")
        self.rates.pub("vel_3", twist(1e308, -1e308), rate=20)  # finite: forwarded, the base's limits apply
        self.wait_output(twist(1e308, -1e308), "a huge but finite Twist to pass")
        complaints = [text for text in self.warnings if "input3" in text and "dropped" in text]
        self.assertEqual(len(complaints), 1, f"expected one warning for input3, got {complaints}")
        wait_for(lambda: [text for text in self.warnings if "input3" in text and "forwarded" in text],
                 what="the warning about input3's huge value")
        huge = [text for text in self.warnings if "input3" in text and "forwarded" in text]
        self.assertEqual(len(huge), 1, f"expected one warning about the huge value, got {huge}")
        # A Bool whose byte is 255 reads true: the lock engages.
        self.rates.pub("lock_2", Bool(255))
        self.rates.pub("vel_1", twist(2.0), rate=10)
        time.sleep(SETTLE)
        self.assertNotIn(twist(2.0), self.since_mark(), "input1 passed under lock_2 sent as 255")

    def test_diagnostics(self):
        wait_for(lambda: self.diagnostics, what="a message on /diagnostics")
        status = self.diagnostics[-1].status[0]
        values = {value.key: value.value for value in status.values}
        self.assertEqual((status.name, status.message, status.hardware_id), ("twist_mux: Twist mux status", "ok",
                                                                           "none"))
        self.assertIn("listening to vel_1 @ 0.700000s with priority #5", values["velocity input1"])
        self.assertIn("lock emergency_255", values)
        self.assertEqual(values["current priority"], "0")


def load_tests(loader, tests, pattern):
    return unittest.TestSuite(loader.loadTestsFromTestCase(case) for case in (TwistMuxSystem, JoystickRelay,
                                                                                MarkerServer))


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "twist_mux_system", "__main__")
