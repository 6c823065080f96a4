#!/usr/bin/env python3
"""A scenario that hangs, for the timeout test: one line, then sleep for ever (nothing heavy imported first, so
the line is out long before the timeout even on a loaded machine)."""
import time

print("hanging on purpose", flush=True)
while True:
    time.sleep(1)
