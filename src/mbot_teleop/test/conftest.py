"""Make the package importable from its source tree, without a catkin build."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, 'src'))

# Needs the simulator and its /clock: it runs only under `rostest mbot_teleop teleop_drive.test`.
collect_ignore = ['test_teleop_drive.py']
