"""The loop's publishers through the writer process (loop_publishing.py, wire_writer.py), against rospy
subscribers: order, header.seq, messages sent as numpy records, a departed subscriber, a new one,
unregistering, stopping, a dead writer."""
import os
import sys

from ros_processes import TESTS, run

NODE = os.path.join(TESTS, "integration", "loop_publishing_node.py")


def test_loop_publishing_writes_through_the_writer_process(ros_env):
    result = run([sys.executable, NODE], ros_env, timeout=60)
    print(result.stdout)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.count("figure:") == 8
