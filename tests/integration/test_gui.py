"""The simulator window: PyBullet's GUI opens on a (virtual) display and shows the robot in its Gazebo
colours; without a display, or with headless:=true, the simulator runs without one and says so once."""
import os
import subprocess

import numpy as np
import pytest

from ros_processes import call_service, service_up, wait_until
from xvfb import Xvfb

MIN_ROBOT_PIXELS = 200
# The window's thread draws continuously in software OpenGL: at PyBullet's 1024x768 that was most of the test's CPU.
# At this size the mbot covers about 900 pixels (about 400 at 320x240); the screen is the window's size.
WINDOW_SIZE = (480, 360)


def gazebo_blue_pixels(image) -> int:
    """Pixels of the base's Gazebo/Blue (pure blue, lit and shaded), which nothing else in the scene uses."""
    red, green, blue = (image[:, :, channel].astype(int) for channel in range(3))
    return int(np.count_nonzero((blue > 90) & (red < 40) & (green < 40)))


def window_resized(display) -> bool:
    """Whether PyBullet's window is open, and then it is given WINDOW_SIZE."""
    command = ["xdotool", "search", "--name", "^Bullet Physics", "windowsize", "%@", *map(str, WINDOW_SIZE)]
    return subprocess.run(command, env=dict(os.environ, DISPLAY=display), capture_output=True,
                          timeout=10).returncode == 0


def spawned(ros_env):
    return (service_up(ros_env, "/gazebo/get_world_properties")
            and "mbot" in call_service(ros_env, "/gazebo/get_world_properties")["model_names"])


def test_window_shows_the_robot_in_gazebo_blue(ros_env, launch, tmp_path):
    screenshot = tmp_path / "pybullet_gui.png"
    with Xvfb(tmp_path / "xvfb.log", screen="{}x{}x24".format(*WINDOW_SIZE)) as server:
        ros_env.update(server.environment({}))
        simulation = launch("mbot_gazebo", "view_mbot_gazebo_empty_world.launch", "gui:=true")
        wait_until(lambda: window_resized(server.display), 90, f"the simulator's window (see {simulation.log_path})",
                   interval=0.25)
        wait_until(lambda: spawned(ros_env), 90, f"the mbot to spawn (see {simulation.log_path})", interval=0.25)

        def blue_robot():
            pixels = gazebo_blue_pixels(server.screenshot(screenshot))
            return pixels if pixels >= MIN_ROBOT_PIXELS else 0
        pixels = wait_until(blue_robot, 60, f"the blue mbot in the window (screenshot {screenshot})", interval=0.25)
        print(f"figure: the mbot on {pixels} Gazebo/Blue pixels of the {WINDOW_SIZE} window")
        if os.environ.get("MBOT_SCREENSHOT_DIR"):
            server.screenshot(os.path.join(os.environ["MBOT_SCREENSHOT_DIR"], "pybullet_gui.png"))
    # The simulator's start-up line ends with its mode.
    started = [line for line in simulation.log_path.read_text().splitlines() if "real-time factor" in line]
    assert len(started) == 1 and started[0].rstrip().endswith(", GUI"), started


@pytest.mark.parametrize("arguments, reason", [
    (("gui:=true",), "no DISPLAY is set"),
    (("gui:=true", "headless:=true"), "headless:=true"),
])
def test_no_window_without_a_display_or_when_headless(ros_env, launch, arguments, reason):
    ros_env.pop("DISPLAY", None)
    simulation = launch("mbot_sim_bridge", "empty_world.launch", *arguments)
    wait_until(lambda: "running without a window" in simulation.log_path.read_text(), 60, "the bridge's notice")
    notices = [line for line in simulation.log_path.read_text().splitlines() if "without a window" in line]
    assert len(notices) == 1 and reason in notices[0], notices
    assert "headless" in simulation.log_path.read_text().split("world ")[-1]
