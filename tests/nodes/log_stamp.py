#!/usr/bin/env python3
"""Prints "ready" once subscribed to every publisher of /rosout, then the stamp (sec.nsec) of the first message
from /gazebo whose text contains the first argument, and exits."""
import sys
import threading
import time

import rosgraph
import rospy
from rosgraph_msgs.msg import Log


def main():
    text = sys.argv[1]
    rospy.init_node("log_stamp", anonymous=True, disable_signals=True)
    found = []
    arrived = threading.Event()

    def keep(message):
        if message.name == "/gazebo" and text in message.msg:
            found.append(message.header.stamp)
            arrived.set()

    subscriber = rospy.Subscriber("/rosout", Log, keep)
    master = rosgraph.Master(rospy.get_name())
    deadline = time.monotonic() + 30
    while True:
        publishers = next((nodes for topic, nodes in master.getSystemState()[0] if topic == "/rosout"), [])
        if "/gazebo" in publishers and subscriber.get_num_connections() >= len(publishers):
            break
        if time.monotonic() > deadline:
            raise SystemExit("not connected to /gazebo's /rosout within 30 s")
        time.sleep(0.01)
    print("ready", flush=True)
    if not arrived.wait(30):
        raise SystemExit(f"no /rosout message from /gazebo containing '{text}' within 30 s")
    print(f"{found[0].secs}.{found[0].nsecs:09d}", flush=True)


if __name__ == "__main__":
    main()
