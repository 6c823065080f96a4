"""Starting and stopping ROS processes from pytest: free ports, a private master, clean shutdown.

A module of its own (not conftest.py) so that test modules can import it by name.
"""
import os
import signal
import socket
import subprocess
import time

TESTS = os.path.dirname(os.path.abspath(__file__))


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def master_answers(environment) -> bool:
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


def run(command, environment, timeout=90, stdin=None):
    """Run a ROS command line to completion; returns the CompletedProcess (text output)."""
    return subprocess.run(command, env=environment, capture_output=True, text=True, timeout=timeout, stdin=stdin)
