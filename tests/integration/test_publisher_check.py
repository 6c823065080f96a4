"""publisher_check: a second /joint_states publisher beside the simulator's (the course's joint_state_publisher) is
reported once, naming the node, what it sends and the launch-file fix; the loop's own messages raise nothing. The
check runs in publisher_check_loop.py, a node that calls it as the bridge's loop does."""
import os
import subprocess
import sys

import pytest
from mbot_sim_bridge.processes import stop_process_group

from ros_processes import TESTS, rosrun, run, wait_until

CHECK_LOOP = os.path.join(TESTS, "integration", "publisher_check_loop.py")
URDF = """<robot name="mbot"><link name="base_link"/>
  <link name="left_wheel_link"/><link name="right_wheel_link"/><link name="back_caster_link"/>
  <joint name="left_wheel_joint" type="continuous"><parent link="base_link"/><child link="left_wheel_link"/></joint>
  <joint name="right_wheel_joint" type="continuous"><parent link="base_link"/><child link="right_wheel_link"/></joint>
  <joint name="back_caster_joint" type="continuous"><parent link="base_link"/><child link="back_caster_link"/></joint>
</robot>"""


@pytest.fixture
def processes(ros_env, tmp_path):
    started = []

    def start(name, command):
        log_path = tmp_path / (name + ".log")
        with open(log_path, "w") as log:
            started.append(subprocess.Popen(command, env=ros_env, stdout=log, stderr=subprocess.STDOUT,
                                            start_new_session=True))
        return log_path

    yield start
    for process in started:
        stop_process_group(process)


SENDS = {"true": "zero positions for left_wheel_joint, right_wheel_joint, back_caster_joint",
         "false": "joint names without positions"}


@pytest.mark.parametrize("default_positions", sorted(SENDS))
def test_second_joint_states_publisher_is_reported_once(ros_env, processes, default_positions):
    assert run(["rosparam", "set", "robot_description", URDF], ros_env).returncode == 0
    loop_log = processes("check_loop", [sys.executable, CHECK_LOOP])
    processes("joint_state_publisher", rosrun("joint_state_publisher", "joint_state_publisher",
                                             "_publish_default_positions:=" + default_positions))
    wait_until(lambda: "second publisher" in loop_log.read_text(), 60, "the check's warning")
    # Three more checks go by without a second warning.
    wait_until(lambda: _checks_after_warning(loop_log.read_text()) >= 3, 60, "three more checks")
    text = loop_log.read_text()
    assert text.count("second publisher") == 1, text
    line = next(line for line in text.splitlines() if "second publisher" in line)
    assert "/joint_states has a second publisher, node /joint_state_publisher" in line
    assert SENDS[default_positions] in line
    assert 'Remove that node from the launch file' in line and '<node name="joint_state_publisher"' in line


def _checks_after_warning(text):
    return text.split("second publisher", 1)[-1].count("check started")
