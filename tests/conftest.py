"""pytest fixtures for tests that need ROS: a private master on a free port, the bridge under roslaunch."""
import os
import signal
import socket
import subprocess
import time

import pytest

TESTS = os.path.dirname(os.path.abspath(__file__))
# rostest nodes: run by the .test files, not collected by pytest.
collect_ignore = ["nodes"]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _master_answers(environment) -> bool:
    check = "import rosgraph, sys; sys.exit(0 if rosgraph.is_master_online() else 1)"
    return subprocess.run(["python3", "-c", check], env=environment).returncode == 0


def wait_until(condition, timeout, what):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))


def stop(process):
    """SIGINT the whole process group (as Ctrl-C would), then make sure it is gone."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


@pytest.fixture
def ros_env(tmp_path):
    """An environment whose ROS_MASTER_URI points at a master of its own, stopped after the test."""
    environment = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % _free_port(), ROS_LOG_DIR=str(tmp_path),
                       PYTHONUNBUFFERED="1")
    port = environment["ROS_MASTER_URI"].rsplit(":", 1)[1]
    master = subprocess.Popen(["rosmaster", "--core", "-p", port], env=environment, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        wait_until(lambda: _master_answers(environment), 30, "the ROS master")
        yield environment
    finally:
        stop(master)


def run(command, environment, timeout=90, stdin=None):
    """Run a ROS command line to completion; returns the CompletedProcess (text output)."""
    return subprocess.run(command, env=environment, capture_output=True, text=True, timeout=timeout, stdin=stdin)


@pytest.fixture
def launch(ros_env):
    """Start roslaunch with the given arguments; every launch is stopped after the test."""
    processes = []

    def start(*arguments):
        process = subprocess.Popen(["roslaunch", *arguments], env=ros_env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, start_new_session=True)
        processes.append(process)
        return process

    yield start
    for process in processes:
        stop(process)
