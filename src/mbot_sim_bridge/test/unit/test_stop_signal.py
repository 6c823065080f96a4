"""SIGINT sets a stop Event even when it arrives while the main thread holds that Event's lock
(inside its own ``wait``), where setting the Event in the handler itself hangs for ever; a process group that
ignores SIGINT is stopped with SIGTERM."""
import signal
import subprocess
import sys
import time

from mbot_sim_bridge.processes import ignores_signal, stop_process_group

# The signal is raised while the main thread holds the Event's condition lock, as it does for a moment in wait().
CHILD = """
import os, signal
from mbot_sim_bridge.processes import stop_on_signals
stop = stop_on_signals()
with stop._cond:
    os.kill(os.getpid(), signal.SIGINT)
    for _ in range(1000):
        pass  # the handler runs between these bytecodes, lock held
print("stopped" if stop.wait(5) else "not stopped")
"""


def test_signal_while_the_event_lock_is_held_still_stops():
    result = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=20)
    assert result.stdout.strip() == "stopped", result.stdout + result.stderr


def test_sigterm_stops_too():
    child = CHILD.replace("signal.SIGINT", "signal.SIGTERM")
    result = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, timeout=20)
    assert result.stdout.strip() == "stopped", result.stdout + result.stderr


# A child that ignores SIGINT, as every process started from a script's background job does.
IGNORING = """
import signal, time
signal.signal(signal.SIGINT, signal.SIG_IGN)
print("ignoring", flush=True)
time.sleep(60)
"""


def test_a_group_that_ignores_sigint_is_stopped_with_sigterm_without_waiting_for_the_kill():
    child = subprocess.Popen([sys.executable, "-c", IGNORING], stdout=subprocess.PIPE, text=True,
                             start_new_session=True)
    try:
        assert child.stdout.readline().strip() == "ignoring"
        assert ignores_signal(child.pid, signal.SIGINT) and not ignores_signal(child.pid, signal.SIGTERM)
        started = time.monotonic()
        assert stop_process_group(child, timeout=10.0), "it had to be killed"
        assert time.monotonic() - started < 5.0
        assert child.returncode == -signal.SIGTERM
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
        child.stdout.close()


def test_a_process_that_is_gone_ignores_nothing():
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    assert not ignores_signal(child.pid, signal.SIGINT)
