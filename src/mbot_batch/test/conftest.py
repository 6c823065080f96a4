"""The workspace's test helpers (tests/ros_processes.py) for the batch tests."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, os.pardir, "tests"))
