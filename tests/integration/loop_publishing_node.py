#!/usr/bin/env python3
"""Drives loop_publishing against real rospy subscribers in this process; prints one 'figure:' line per check,
or exits non-zero naming the check that failed (test_loop_publishing.py)."""
import io
import os
import sys
import time

import numpy as np
import rospy
from mbot_sim_bridge import loop_publishing
from mbot_sim_bridge.processes import wait_until
from mbot_sim_bridge.core.sensors.imu import ImuReading, ImuReadings
from mbot_sim_bridge.plugins.messages import imu_message, imu_records
from geometry_msgs.msg import PointStamped
from sensor_msgs.msg import Imu
from std_msgs.msg import String


def serialized(message) -> bytes:
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


def check_records(publishing):
    """Messages serialized as numpy records (the every-step IMU's) arrive as genpy would have made them,
    numbered in turn with a message published the usual way."""
    imu = loop_publishing.LoopPublisher("/imu", Imu)
    received = []
    rospy.Subscriber("/imu", Imu, received.append)
    wait_until(lambda: imu.get_num_connections() == 1, 10.0, "the connection to /imu")
    rng = np.random.default_rng(3)
    orientations = rng.normal(size=(3, 4))
    readings = ImuReadings(np.array([0.001, 41.0025, 1e6 + 0.0000005]), orientations / np.linalg.norm(
        orientations, axis=1)[:, None], rng.normal(size=(3, 3)), rng.normal(size=(3, 3)), 0.25)
    rows = [ImuReading(float(readings.stamps[row]), tuple(readings.orientations[row]),
                       tuple(readings.angular_velocities[row]), tuple(readings.linear_accelerations[row]), 0.25)
            for row in range(3)]
    imu.publish_records(imu_records(readings, "imu_link"))
    imu.publish(imu_message(rows[0], "imu_link"))
    publishing.sync()
    wait_until(lambda: len(received) == 4, 10.0, "four /imu messages")
    for seq, (message, row) in enumerate(zip(received, rows + rows[:1]), start=1):
        expected = imu_message(row, "imu_link")
        expected.header.seq = seq
        if serialized(message) != serialized(expected):
            sys.exit(f"/imu message {seq} differs from genpy's:\n{message}\nexpected\n{expected}")
    print("figure: three Imu readings sent as numpy records arrived as genpy's messages, header.seq 1 to 3, "
          "then a genpy message as 4")


def main():
    rospy.init_node("loop_publishing_check", disable_signals=True)
    publishing = loop_publishing.start()
    chatter = loop_publishing.LoopPublisher("/chatter", String)
    stamped = loop_publishing.LoopPublisher("/stamped", PointStamped)
    received, headers = [], []
    subscriber = rospy.Subscriber("/chatter", String, lambda message: received.append(message.data))
    rospy.Subscriber("/stamped", PointStamped, lambda message: headers.append(message.header.seq))
    wait_until(lambda: chatter.get_num_connections() == 1 and stamped.get_num_connections() == 1, 10.0, "connections")

    for number in range(300):
        chatter.publish(String(data=str(number)))
        stamped.publish(PointStamped())
        if number % 7 == 0:
            publishing.flush()
    publishing.sync()
    wait_until(lambda: len(received) == 300 and len(headers) == 300, 10.0, "300 messages on each topic")
    if received != [str(number) for number in range(300)] or headers != list(range(1, 301)):
        sys.exit(f"messages out of order or header.seq not counted: {received[:5]} {headers[:5]}")
    print("figure: 300 messages on each of two topics arrived in order, header.seq 1 to 300")
    check_records(publishing)

    # A subscriber that leaves is found by the writer and its connection closed in rospy.
    subscriber.unregister()

    def departed() -> bool:
        if chatter.get_num_connections() == 0:
            return True
        chatter.publish(String(data="x"))  # the writer finds the closed socket when it writes to it
        publishing.flush()
        return False
    wait_until(departed, 10.0, "the departed subscriber's connection closed")
    print("figure: a departed subscriber's connection is closed in rospy")

    # A new subscriber receives, on a new connection.
    again = []
    rospy.Subscriber("/chatter", String, lambda message: again.append(message.data))
    wait_until(lambda: chatter.get_num_connections() == 1, 10.0, "the new connection")
    chatter.publish(String(data="again"))
    publishing.sync()
    wait_until(lambda: again == ["again"], 10.0, "a message on the new connection")
    print("figure: a new subscriber receives on its new connection")

    # A publisher that unregisters: the writer closes its copies of the publisher's sockets too.
    def writer_descriptors():
        return len(os.listdir(f"/proc/{publishing.process.pid}/fd"))
    before = writer_descriptors()
    stamped.unregister()
    publishing.sync()
    if writer_descriptors() != before - 1:
        sys.exit(f"the writer holds {writer_descriptors()} descriptors after unregistering, {before} before")
    print("figure: unregistering a publisher closes the writer's copy of its connection")

    started = time.monotonic()
    process = publishing.process
    loop_publishing.stop()
    if process.poll() is None:
        sys.exit("the writer process outlived stop()")
    print(f"figure: the writer stopped {time.monotonic() - started:.3f} s after stop()")

    # A writer that dies is reported by the loop's next flush, not by a plugin's publish.
    publishing = loop_publishing.start()
    late = loop_publishing.LoopPublisher("/late", String)
    rospy.Subscriber("/late", String, lambda message: None)
    wait_until(lambda: late.get_num_connections() == 1, 10.0, "the connection to /late")
    publishing.process.kill()
    publishing.process.wait()
    late.publish(String(data="into the void"))
    try:
        publishing.flush()
        sys.exit("flush() after the writer died raised nothing")
    except loop_publishing.WriterStopped as error:
        print(f"figure: a dead writer is reported: {error}")
    loop_publishing.stop()

    # Without a writer process, records go out through rospy's own publisher.
    direct = loop_publishing.LoopPublisher("/imu_direct", Imu)
    received = []
    rospy.Subscriber("/imu_direct", Imu, received.append)
    wait_until(lambda: direct.get_num_connections() == 1, 10.0, "the connection to /imu_direct")
    readings = ImuReadings(np.array([0.5, 0.501]), np.array([[0.0, 0.0, 0.0, 1.0]] * 2), np.ones((2, 3)),
                           np.zeros((2, 3)), 0.0)
    direct.publish_records(imu_records(readings, "imu_link"))
    wait_until(lambda: len(received) == 2, 10.0, "two /imu_direct messages")
    if [message.header.stamp.to_sec() for message in received] != [0.5, 0.501] or \
            received[1].angular_velocity.z != 1.0 or received[1].header.frame_id != "imu_link":
        sys.exit(f"records published without a writer arrived wrong: {received}")
    print("figure: without a writer process, records are published through rospy and arrive whole")


if __name__ == "__main__":
    main()
