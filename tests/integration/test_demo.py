"""./mbot demo's job, end to end: the tour runs (in the room), the summary prints, and the picture's drawn path is
the odometry the demo recorded; with --gui the simulator shows its window for a short tour; --arm follows its
trajectory and draws it."""
import csv
import os

import numpy as np
import pytest
from mbot_gazebo.demo import main as demo_main
from mbot_gazebo.demo_plot import PATH_COLOUR, PlotFrame
from PIL import Image

from ros_processes import rosrun, run
from xvfb import Xvfb

MARKER_PIXELS = 25
SUMMARY = ("distance driven:", "tour:", "scans received:", "final odometry:", "picture:")


def evenly_along(path, count):
    """``count`` points spaced evenly by distance along ``path`` (by index they bunch where the robot stood)."""
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    stations = np.linspace(0.0, travelled[-1], count)
    return np.column_stack([np.interp(stations, travelled, path[:, axis]) for axis in (0, 1)])


@pytest.fixture
def demo_env(tmp_path):
    """The demo's environment: it starts a master of its own (a ros_env fixture's would go unused)."""
    return dict(os.environ, ROS_LOG_DIR=str(tmp_path))


def test_demo_tours_the_room_and_draws_its_odometry(demo_env, tmp_path):
    picture = tmp_path / "demo.png"
    result = run(rosrun("mbot_gazebo", "mbot_demo", "--world", "room", "--out", str(picture)), demo_env,
                 timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    for line in SUMMARY:
        assert line in result.stdout, result.stdout
    chatter = [line for line in (result.stdout + result.stderr).splitlines() if line.startswith(("[DEBUG]", "[INFO]"))]
    assert not chatter, f"plugin logs belong in the log folder, not on the console: {chatter[:3]}"
    distance = float(result.stdout.split("distance driven:")[1].split()[0])
    assert distance > 5.0, "the tour is about 8 m"
    assert "mbot demo: room" in result.stdout + result.stderr

    with open(tmp_path / "demo_odometry.csv") as stream:
        path = np.array([[float(row["x_m"]), float(row["y_m"])] for row in csv.DictReader(stream)])
    frame = PlotFrame.load(str(tmp_path / "demo_frame.json"))
    with Image.open(picture) as image:
        pixels = np.asarray(image.convert("RGB")).astype(int)
    assert pixels.shape[:2] == (frame.height, frame.width)
    colour = np.array([int(PATH_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])
    points = frame.to_pixels(evenly_along(path, 200))
    ends = frame.to_pixels(path[[0, -1]])
    # The start and end markers (and the final heading arrow) are drawn over the path around its two ends.
    visible = [point for point in points if np.min(np.hypot(*(ends - point).T)) > MARKER_PIXELS]
    drawn = 0
    for column, row in np.array(visible).astype(int):
        patch = pixels[max(row - 2, 0):row + 3, max(column - 2, 0):column + 3]
        drawn += bool(np.any(np.abs(patch - colour).sum(axis=2) < 60))
    assert len(visible) > 100
    assert drawn >= 0.98 * len(visible), f"{drawn} of {len(visible)} odometry points are on the drawn path"
    if os.environ.get("MBOT_SCREENSHOT_DIR"):
        Image.open(picture).save(os.path.join(os.environ["MBOT_SCREENSHOT_DIR"], "demo.png"))


def summary_figure(stdout, label):
    return float(stdout.split(label)[1].split()[0])


def test_demo_gui_shows_the_window_for_a_short_tour(demo_env, tmp_path):
    """--gui starts the simulator with its window (its start-up line ends with the mode); --sim-seconds 0.25 ends the
    tour after 0.25 s of sim time, within one control period (50 ms), having driven forward. Short: with the window
    the simulation ran at 0.05x real time (software OpenGL on a loaded machine). In the empty world: the window's
    software rendering of the play ground's meshes cost 16 CPU seconds of this run, the empty world's 7 (the
    tour itself runs in the room above)."""
    picture = tmp_path / "demo.png"
    with Xvfb(tmp_path / "xvfb.log") as server:
        result = run(rosrun("mbot_gazebo", "mbot_demo", "--gui", "--world", "empty", "--sim-seconds", "0.25",
                            "--out", str(picture)),
                     dict(demo_env, DISPLAY=server.display, LIBGL_ALWAYS_SOFTWARE="1"), timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    started = [line for line in (tmp_path / "demo_logs" / "roslaunch.log").read_text().splitlines()
               if "real-time factor" in line]
    assert len(started) == 1 and started[0].rstrip().endswith(", GUI"), started
    assert 0.25 <= summary_figure(result.stdout, "tour:") < 0.3 + 1e-6, result.stdout
    # Forward at 0.4 m/s at most, from rest: less than 0.1 m, and the wheels have turned (printed to 1 cm).
    assert 0.01 <= summary_figure(result.stdout, "distance driven:") < 0.1, result.stdout
    assert picture.is_file()


@pytest.mark.parametrize("value", ["nan", "-1", "0"])
def test_demo_refuses_a_tour_length_that_is_not_a_positive_number(capsys, value):
    with pytest.raises(SystemExit) as exit_info:
        demo_main(["--sim-seconds", value])
    assert exit_info.value.code == 2
    assert f"--sim-seconds must be a positive number of seconds, not {float(value)}" in capsys.readouterr().err


def joint_errors(stdout, label):
    return [float(error) for error in stdout.split(label)[1].splitlines()[0].split(",")]


def test_demo_arm_follows_its_trajectory_and_draws_it(demo_env, tmp_path):
    picture = tmp_path / "arm.png"
    result = run(rosrun("mbot_gazebo", "mbot_demo", "--arm", "--out", str(picture)), demo_env, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "result: SUCCESSFUL" in result.stdout
    largest = joint_errors(result.stdout, "largest tracking error per joint (rad):")
    final = joint_errors(result.stdout, "final error per joint (rad):")
    assert len(largest) == len(final) == 6
    # What the plot shows: measured 0.035 rad at the most on the way and 0.0005 rad at the end.
    assert max(largest) < 0.1 and max(final) < 0.01, result.stdout
    with Image.open(picture) as image:
        assert image.size == (1200, 700)
        pixels = np.asarray(image.convert("RGB")).astype(int)
    # Both curves are drawn: matplotlib's tab:blue (commanded) and tab:orange (actual).
    for colour in ((31, 119, 180), (255, 127, 14)):
        assert np.count_nonzero(np.abs(pixels - colour).sum(axis=2) < 30) > 1000, colour
