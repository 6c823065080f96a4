"""The ROS layer's background work and shutdown, without a master: the joint_states check goes on whatever names
the robots' namespaces hold (a bad one ended its thread for the rest of the run), and a loop publisher that rospy's
shutdown closed from another thread (the master hands the node's name to a new /gazebo) takes no more messages
instead of raising in the loop."""
import pytest
import rospy
from rosgraph_msgs.msg import Clock

from mbot_sim_bridge import loop_publishing, publisher_check


class _MasterWithJointStates:
    """rosgraph.Master's stand-in: the node publishes /good/joint_states."""

    def __init__(self, caller_id):
        self.caller_id = caller_id

    def getSystemState(self):
        return [[["/good/joint_states", [self.caller_id]]], [], []]


@pytest.mark.parametrize("namespace", ["~priv", "a b", "/../..", "//", ""])
def test_the_joint_states_check_goes_on_after_any_namespace(monkeypatch, namespace):
    monkeypatch.setattr(publisher_check.rosgraph, "Master", _MasterWithJointStates)
    check = publisher_check._PublisherCheck()
    check._busy = True  # as start() leaves it for the thread
    check._check("/gazebo", (namespace, "/good"))
    assert check._busy is False, "the next check would never start"


def test_a_publisher_closed_by_rospy_shutdown_takes_no_messages():
    publishing = loop_publishing.LoopPublishing()
    try:
        publisher = rospy.Publisher("/closed_by_shutdown", Clock, queue_size=None)
        impl = publisher.impl
        impl.close()  # what rospy's shutdown does to every topic, in the thread of the master's request
        publishing.publish(impl, Clock())
        assert not publishing._batch, "a message of a closed publisher was batched"
        publishing.flush()
        assert publishing.process.poll() is None, "the writer stopped"
    finally:
        publishing.close()
