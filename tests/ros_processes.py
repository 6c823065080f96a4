"""Helpers for the tests that run ROS command lines (a module, not conftest.py, so tests can import it)."""
import os
import subprocess
import time

TESTS = os.path.dirname(os.path.abspath(__file__))


def wait_until(condition, timeout, what):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")


def run(command, environment, timeout=90, stdin=None):
    """Run a ROS command line to completion; returns the CompletedProcess (text output)."""
    return subprocess.run(command, env=environment, capture_output=True, text=True, timeout=timeout, stdin=stdin)
