"""rviz shows what the course's camera and kinect see: their launch files (gui:=false) with the shipped
mbot_with_camera / mbot_with_kinect configs, on a private X server with software OpenGL.

The camera picture is recognised by its sky: the bridge draws Gazebo's background grey (178, 178, 178)
where nothing is in view, a colour neither rviz's panels nor its 3D view use. The 3D view must show the
robot, and for the kinect also the point cloud in front of it; rviz's output has no TF errors but the
repeated wheel states of the course's joint_state_publisher. MBOT_SCREENSHOT_DIR, if set, receives a copy
of each screenshot.
"""
import os

import numpy as np
import pytest
import yaml

from ros_processes import TESTS
from test_rviz import (CAMERA_CONFIGS, assert_no_tf_errors, colour_count, keep_screenshot, parse_colour, running_rviz,
                       view_3d)
from test_rviz import scenes, screen  # noqa: F401 (fixtures: the tests name them)

CONFIG_DIR = os.path.join(os.path.dirname(TESTS), "src", "mbot_description", "config")
SKY = np.array((178, 178, 178))
MIN_SKY_PIXELS = 2000  # the image panel's picture, upper part
MIN_ROBOT_PIXELS = 100
MIN_CLOUD_PIXELS = 2000
CASES = {
    "camera": ("view_mbot_with_camera_gazebo.launch", "mbot_with_camera.rviz", {"/camera/image_raw"}),
    "kinect": ("view_mbot_with_kinect_gazebo.launch", "mbot_with_kinect.rviz",
               {"/kinect/rgb/image_raw", "/kinect/depth/points"}),
}


def sky_pixels(image):
    """Pixels of the camera picture's sky (noise of a few levels allowed) anywhere on the screen."""
    return int(np.all(np.abs(image.astype(int) - SKY) <= 8, axis=2).sum())


def cloud_pixels(view):
    """3D-view pixels in the picture's greys (the kinect's cloud takes the colours of what it sees: the play
    ground's grey floor and barriers); the dark background, the half-transparent grid and the coloured robot
    and TF axes are outside that range."""
    pixels = view.astype(int)
    spread = pixels.max(axis=2) - pixels.min(axis=2)
    return int(((spread < 12) & (pixels.min(axis=2) >= 120) & (pixels.max(axis=2) <= 200)).sum())


def test_these_are_the_configs_test_rviz_leaves_out():
    assert {config for _, config, _ in CASES.values()} == CAMERA_CONFIGS


@pytest.mark.parametrize("case", sorted(CASES))
def test_rviz_shows_the_camera_picture(case, scenes, screen, tmp_path):  # noqa: F811 (test_rviz's fixtures)
    launch_file, config_name, topics = CASES[case]
    config = os.path.join(CONFIG_DIR, config_name)
    with open(config) as stream:
        displays = yaml.safe_load(stream)["Visualization Manager"]
    background = parse_colour(displays["Global Options"]["Background Color"])

    ros_env, master, robot_colour = scenes.get(((launch_file,), "/robot_description", topics | {"/odom", "/tf"}))

    def drawn(image):
        view = view_3d(image, background)
        return (sky_pixels(image) >= MIN_SKY_PIXELS and view is not None
                and colour_count(view, robot_colour) >= MIN_ROBOT_PIXELS
                and (case != "kinect" or cloud_pixels(view) >= MIN_CLOUD_PIXELS))

    screenshot = tmp_path / ("rviz_" + config_name.replace(".rviz", ".png"))
    environment = screen.environment(ros_env, HOME=str(tmp_path))
    # The picture arrives slowly on a loaded machine: a 1280x720 frame is rendered on the CPU.
    with running_rviz(config, environment, master, screen, screenshot, drawn, 120, 2.0) as (_, image, log_path):
        keep_screenshot(screenshot)
    where = f"(screenshot {screenshot}, rviz output {log_path})"
    view = view_3d(image, background)
    assert view is not None, "no 3D view " + where
    sky, robot = sky_pixels(image), colour_count(view, robot_colour)
    cloud = cloud_pixels(view)
    print(f"figure: rviz {case}: {sky} picture-sky pixels, {robot} robot pixels, {cloud} cloud pixels in the 3D view")
    assert sky >= MIN_SKY_PIXELS, "the camera picture is not in rviz's image panel " + where
    assert robot >= MIN_ROBOT_PIXELS, "the robot is not in the 3D view " + where
    if case == "kinect":
        assert cloud >= MIN_CLOUD_PIXELS, "the point cloud is not in the 3D view " + where
    # The course's camera and kinect launch files start joint_state_publisher beside the simulator, whose second
    # set of wheel states rviz reports as repeated data (as it does with Gazebo); anything else is an error.
    assert_no_tf_errors(log_path, expected=("TF_REPEATED_DATA",))
