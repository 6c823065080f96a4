"""pytest fixtures for tests that need ROS: a private master on a free port, roslaunch processes."""
import os
import subprocess

import pytest

from ros_processes import free_port, master_answers, stop, wait_until

# rostest nodes: run by the .test files, not collected by pytest.
collect_ignore = ["nodes"]


@pytest.fixture
def ros_env(tmp_path):
    """An environment whose ROS_MASTER_URI points at a master of its own, stopped after the test."""
    environment = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % free_port(), ROS_LOG_DIR=str(tmp_path),
                       PYTHONUNBUFFERED="1")
    port = environment["ROS_MASTER_URI"].rsplit(":", 1)[1]
    master = subprocess.Popen(["rosmaster", "--core", "-p", port], env=environment, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        wait_until(lambda: master_answers(environment), 30, "the ROS master")
        yield environment
    finally:
        stop(master)


@pytest.fixture
def launch(ros_env, tmp_path):
    """Start roslaunch with the given arguments; every launch is stopped after the test.

    Its output goes to a file (``process.log_path``): a pipe nobody reads would block it once full.
    """
    processes = []

    def start(*arguments):
        log_path = tmp_path / ("roslaunch-%d.log" % len(processes))
        with open(log_path, "w") as log:
            process = subprocess.Popen(["roslaunch", *arguments], env=ros_env, stdout=log,
                                       stderr=subprocess.STDOUT, start_new_session=True)
        process.log_path = log_path
        processes.append(process)
        return process

    yield start
    for process in processes:
        stop(process)
