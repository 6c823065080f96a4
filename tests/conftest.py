"""pytest fixtures for tests that need ROS: a private master on a free port, roslaunch processes."""
import subprocess

import pytest
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group

# rostest nodes: run by the .test files, not collected by pytest.
collect_ignore = ["nodes"]


@pytest.fixture
def ros_env(tmp_path):
    """An environment whose ROS_MASTER_URI points at a master of its own, stopped after the test."""
    with PrivateMaster() as master:
        yield dict(master.environment, ROS_LOG_DIR=str(tmp_path), PYTHONUNBUFFERED="1")


@pytest.fixture
def launch(ros_env, tmp_path):
    """Start roslaunch with the given arguments; every launch is stopped after the test.

    Its output goes to a file (``process.log_path``): a pipe nobody reads would block it once full.
    """
    processes = []

    def start(*arguments):
        log_path = tmp_path / (f"roslaunch-{len(processes)}.log")
        with open(log_path, "w") as log:
            process = subprocess.Popen(["roslaunch", *arguments], env=ros_env, stdout=log,
                                       stderr=subprocess.STDOUT, start_new_session=True)
        process.log_path = log_path
        processes.append(process)
        return process

    yield start
    for process in processes:
        stop_process_group(process)
