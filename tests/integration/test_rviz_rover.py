"""The rover in rviz with its shipped config (fixed frame odom, as the README shows): drawn at rest, then
moved in the picture by ``rostopic pub /cmd_vel`` through twist_mux, with no TF errors. The rover runs without
its 3D lidar; odom -> base_link comes from robot_localization's EKF, as Clearpath's launch has it.
MBOT_SCREENSHOT_DIR, if set, receives the two screenshots."""
import os
import shutil
import subprocess

import numpy as np
import pytest
import rosgraph
import yaml
from mbot_sim_bridge.processes import stop_process_group

from ros_processes import TESTS, wait_until
from test_rviz import (DRAW_TIMEOUT, MASTER_POLL, MIN_ROBOT_PIXELS, assert_no_tf_errors, base_link_colour,
                       colour_mask, parse_colour, published, running_rviz, view_3d, watch)
from xvfb import Xvfb

pytestmark = pytest.mark.long

CONFIG = os.path.join(os.path.dirname(TESTS), "src", "rover_description", "config", "rover.rviz")
TOPICS = {"/rover_velocity_controller/odom", "/tf", "/tf_static", "/twist_marker_server/update"}
# 0.5 m/s for a few seconds: the rover's picture must move by this many pixels (about 0.3 m at this view).
MIN_SHIFT_PIXELS = 25
STEADY = 1.0


def robot_centre(image, background, colour):
    view = view_3d(image, background)
    if view is None:
        return None
    rows, columns = np.nonzero(colour_mask(view, colour))
    return None if len(rows) < MIN_ROBOT_PIXELS else np.array([rows.mean(), columns.mean()])


def test_rviz_shows_the_rover_driven_by_cmd_vel(ros_env, launch, tmp_path):
    with open(CONFIG) as stream:
        options = yaml.safe_load(stream)["Visualization Manager"]["Global Options"]
    assert options["Fixed Frame"] == "odom"
    background = parse_colour(options["Background Color"])
    simulation = launch("rover_gazebo", "rover_empty_world.launch", "gui:=false", "lidar_3d_enabled:=false")
    master = rosgraph.Master("/test_rviz_rover", master_uri=ros_env["ROS_MASTER_URI"])
    wait_until(lambda: published(master) >= TOPICS, 60, f"the rover's {', '.join(sorted(TOPICS))} "
               f"(see {simulation.log_path})", interval=MASTER_POLL)
    colour = base_link_colour(master.getParam("/robot_description"))
    shots = [tmp_path / "rviz_rover_at_rest.png", tmp_path / "rviz_rover_driven.png"]
    with Xvfb(tmp_path / "xvfb.log") as server:
        environment = server.environment(ros_env, HOME=str(tmp_path))
        with running_rviz(CONFIG, environment, master, server, shots[0],
                          lambda image: robot_centre(image, background, colour) is not None, DRAW_TIMEOUT,
                          STEADY) as (rviz, image, log_path):
            start = robot_centre(image, background, colour)
            assert start is not None, f"the rover is not drawn at rest (screenshot {shots[0]}, rviz {log_path})"
            # As the README says: rostopic pub at 10 Hz on /cmd_vel, twist_mux's lowest-priority input.
            with open(tmp_path / "rostopic.log", "w") as log:
                driver = subprocess.Popen(["rostopic", "pub", "-r", "10", "/cmd_vel", "geometry_msgs/Twist",
                                           "{linear: {x: 0.5}}"], env=ros_env, stdout=log,
                                          stderr=subprocess.STDOUT, start_new_session=True)

            def moved(image):
                centre = robot_centre(image, background, colour)
                return centre is not None and np.linalg.norm(centre - start) >= MIN_SHIFT_PIXELS
            try:
                image = watch(server, shots[1], moved, DRAW_TIMEOUT, STEADY)
            finally:
                stop_process_group(driver)
            assert rviz.poll() is None, f"rviz exited with {rviz.returncode}:\n{log_path.read_text()}"
    if os.environ.get("MBOT_SCREENSHOT_DIR"):
        os.makedirs(os.environ["MBOT_SCREENSHOT_DIR"], exist_ok=True)
        for shot in shots:
            shutil.copy(shot, os.environ["MBOT_SCREENSHOT_DIR"])
    end = robot_centre(image, background, colour)
    assert end is not None, f"the rover left the picture (screenshot {shots[1]})"
    shift = float(np.linalg.norm(end - start))
    print(f"figure: rover in rviz (fixed frame odom) after /cmd_vel at 0.5 m/s: moved {shift:.0f} px")
    assert shift >= MIN_SHIFT_PIXELS, f"the rover moved {shift:.0f} px in rviz (screenshots {shots})"
    assert_no_tf_errors(log_path)
