#!/usr/bin/env python3
"""drain() after a synchronous publish in the same node, while the subscriber's reader thread holds bytes it
has taken out of the socket for a while before buffering them (as it does when it waits for the GIL under
load): drain must not return before the callback has run. Prints one line per trial: "handled" or "missed"."""
import threading
import time
import warnings

import rospy
from mbot_sim_bridge import subscriptions
from std_msgs.msg import String

READER_DELAY = 0.05
TRIALS = 5


def main():
    rospy.init_node("drain_script", disable_signals=True)
    handled = threading.Event()
    subscriber = subscriptions.TrackedSubscriber("/drain_test", String, lambda message: handled.set(), queue_size=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)
        publisher = rospy.Publisher("/drain_test", String, queue_size=None)
    deadline = time.monotonic() + 30
    while subscriber.get_num_connections() < 1 or publisher.get_num_connections() < 1:
        if time.monotonic() > deadline:
            raise SystemExit("no connection within 30 s")
        time.sleep(0.01)
    def slow_receive(sock, buffer, size):
        """rospy's recv_buff with a pause between taking the bytes out of the socket and buffering them."""
        data = sock.recv(size)
        time.sleep(READER_DELAY)
        buffer.write(data)
        return len(data)
    subscriptions._ROSPY_RECV_BUFF = slow_receive
    for _ in range(TRIALS):
        handled.clear()
        publisher.publish(String(data="x"))
        print("handled" if subscriptions.drain([subscriber], timeout=5.0) and handled.is_set() else "missed",
              flush=True)


if __name__ == "__main__":
    main()
