"""./mbot demo's job, end to end: the tour runs, the summary prints, and the picture's drawn path is the
odometry the demo recorded."""
import csv
import os

import numpy as np
from mbot_gazebo.demo_plot import PATH_COLOUR, PlotFrame
from PIL import Image

from ros_processes import run

MARKER_PIXELS = 25
SUMMARY = ("distance driven:", "tour:", "scans received:", "final odometry:", "picture:")


def evenly_along(path, count):
    """``count`` points spaced evenly by distance along ``path`` (by index they bunch where the robot stood)."""
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    stations = np.linspace(0.0, travelled[-1], count)
    return np.column_stack([np.interp(stations, travelled, path[:, axis]) for axis in (0, 1)])


def test_demo_tours_the_play_ground_and_draws_its_odometry(ros_env, tmp_path):
    picture = tmp_path / "demo.png"
    result = run(["rosrun", "mbot_gazebo", "mbot_demo", "--out", str(picture)], ros_env, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    for line in SUMMARY:
        assert line in result.stdout, result.stdout
    chatter = [line for line in (result.stdout + result.stderr).splitlines() if line.startswith(("[DEBUG]", "[INFO]"))]
    assert not chatter, f"plugin logs belong in the log folder, not on the console: {chatter[:3]}"
    distance = float(result.stdout.split("distance driven:")[1].split()[0])
    assert distance > 5.0, "the tour is about 8 m"

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
