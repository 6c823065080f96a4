"""processes.init_node: rospy.init_node with rospy.impl.init's wait for the master's registration polled every
1 ms instead of every 0.1 s."""
import time

import pytest
import rospy
import rospy.impl.init as rospy_init

from mbot_sim_bridge import processes


def test_init_node_caps_rospy_init_sleeps_and_gives_the_time_module_back(monkeypatch):
    slept, calls = [], []
    monkeypatch.setattr(time, "sleep", slept.append)

    def fake_init_node(name, **options):
        calls.append((name, options))
        rospy_init.time.sleep(0.1)  # start_node's poll for the master's registration
        rospy_init.time.sleep(0.00001)  # its poll for the XML-RPC server
        assert rospy_init.time.monotonic is time.monotonic  # everything else is the time module's
    monkeypatch.setattr(rospy, "init_node", fake_init_node)
    processes.init_node("gazebo", disable_signals=True)
    assert calls == [("gazebo", {"disable_signals": True})]
    assert slept == [0.001, 0.00001]
    assert rospy_init.time is time


def test_the_time_module_comes_back_when_init_node_fails(monkeypatch):
    def failing_init_node(name, **options):
        raise rospy.exceptions.ROSInitException("no master")
    monkeypatch.setattr(rospy, "init_node", failing_init_node)
    with pytest.raises(rospy.exceptions.ROSInitException):
        processes.init_node("gazebo")
    assert rospy_init.time is time
