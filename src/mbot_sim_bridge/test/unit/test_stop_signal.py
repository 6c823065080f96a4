"""SIGINT sets a stop Event even when it arrives while the main thread holds that Event's lock
(inside its own ``wait``), where setting the Event in the handler itself hangs for ever."""
import subprocess
import sys

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
