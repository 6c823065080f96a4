"""Every launch file parses and resolves (roslaunch's own check: args, includes, $(find), node types)."""
import glob
import os

import pytest
import roslaunch.rlutil

from ros_processes import TESTS

LAUNCH_FILES = sorted(glob.glob(os.path.join(os.path.dirname(TESTS), "src", "*", "launch", "*.launch"))
                      + glob.glob(os.path.join(TESTS, "*.test")))


def test_every_package_has_its_launch_files():
    names = {os.path.basename(path) for path in LAUNCH_FILES}
    assert {"view_mbot_gazebo_empty_world.launch", "view_mbot_gazebo_play_ground.launch",
            "view_mbot_gazebo_room.launch", "view_mbot_with_laser_gazebo.launch", "empty_world.launch",
            "display_mbot_base_xacro.launch", "mbot_teleop.launch"} <= names


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=os.path.basename)
def test_launch_file_checks(path):
    assert roslaunch.rlutil.check_roslaunch(path) is None
