#!/usr/bin/env python3
"""A scenario that hangs, for the timeout test: children that the run's end must kill too, each named by the run's
``marker`` parameter (``start_hostile_children``), one line, then sleep for ever (nothing heavy imported first, so
the line is out long before the timeout even on a loaded machine)."""
import subprocess
import sys
import time

SLEEP = "import time; time.sleep(1000)"
# One that ignores SIGTERM, one started with a clean environment (no run token), and a double-forked orphan in a
# session of its own with a clean environment.
HOSTILE_CHILDREN = 3


def start_hostile_children(marker: str):
    """Each child's command line ends with ``marker``; returns once all are started (the orphan's parents gone)."""
    subprocess.Popen([sys.executable, "-c", "import signal; signal.signal(signal.SIGTERM, signal.SIG_IGN); " + SLEEP,
                      marker])
    subprocess.Popen(["env", "-i", sys.executable, "-c", SLEEP, marker])
    subprocess.run(["env", "-i", sys.executable, "-c", "import os; os.fork() and os._exit(0); os.setsid(); "
                    "os.fork() and os._exit(0); " + SLEEP, marker], check=True)


if __name__ == "__main__":
    from mbot_batch import scenario
    marker = scenario.parameters().get("marker")
    if marker:
        start_hostile_children(marker)
    print("hanging on purpose", flush=True)
    while True:
        time.sleep(1)
