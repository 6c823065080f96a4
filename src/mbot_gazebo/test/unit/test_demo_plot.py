"""mbot_gazebo.demo_plot: the PNG shows the path, the lidar hits and the obstacles where the data says."""
import os

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from PIL import Image

from mbot_gazebo.footprints import footprint
from mbot_gazebo.demo_plot import IMAGE_SIZE, OBSTACLE_COLOUR, PATH_COLOUR, SCAN_COLOUR, PlotFrame, draw_demo
from mbot_sim_bridge.core.description.sdf_world import parse_world

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
PLAYGROUND = os.path.join(REPO, "worlds", "playground.world")
LIDAR_RANGE = 6.0
MARKER_CLEARANCE = 12  # pixels: the start and end markers are drawn over the ends of the path


@pytest.fixture(scope="module")
def world():
    return parse_world(PLAYGROUND)


@pytest.fixture(scope="module")
def run():
    """A gentle S-curve from the origin, inside the playground's clear area, with its headings."""
    x = np.linspace(0.0, 3.0, 200)
    y = 0.6 * np.sin(x * np.pi / 3.0) ** 2
    headings = np.arctan2(np.gradient(y), np.gradient(x))
    return np.stack([x, y], axis=1), headings


@pytest.fixture(scope="module")
def scan_points(world, run):
    """Points every 5 cm along the footprint edges within lidar range of the final pose."""
    end = run[0][-1]
    points = []
    for shape in world.shapes:
        outline = np.asarray(footprint(shape))
        for start, stop in zip(outline, np.roll(outline, -1, axis=0)):
            steps = max(2, int(np.linalg.norm(stop - start) / 0.05))
            points.extend(start + (stop - start) * t for t in np.linspace(0.0, 1.0, steps, endpoint=False))
    points = np.array(points)
    return points[np.linalg.norm(points - end, axis=1) <= LIDAR_RANGE]


@pytest.fixture(scope="module")
def drawing(world, run, scan_points, tmp_path_factory):
    out = tmp_path_factory.mktemp("demo_plot") / "demo.png"
    path, headings = run
    frame = draw_demo(world, path, scan_points, str(out), title="playground", headings=headings,
                      summary_lines=["distance driven: 3.2 m", "scans received: 12"])
    return out, frame, np.asarray(Image.open(out).convert("RGB")).astype(int)


def pixels_at(image, frame, points_xy):
    """RGB of the pixel that holds each point (a pixel's column c spans [c, c + 1))."""
    columns, rows = np.floor(frame.to_pixels(points_xy)).astype(int).T
    return image[rows, columns]


def matches(rgb, colour, tolerance=8):
    return np.all(np.abs(rgb - np.round(np.array(to_rgb(colour)) * 255)) <= tolerance, axis=-1)


def test_png_has_the_expected_size_and_content(drawing):
    out, frame, image = drawing
    assert out.is_file()
    assert (frame.width, frame.height) == IMAGE_SIZE
    assert image.shape == (IMAGE_SIZE[1], IMAGE_SIZE[0], 3)
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 100, "too few colours for a drawing"
    assert image.std() > 20


def test_path_colour_lies_under_every_path_point(drawing, run):
    _, frame, image = drawing
    path = run[0]
    pixels = frame.to_pixels(path)
    clear = np.minimum(np.linalg.norm(pixels - pixels[0], axis=1),
                       np.linalg.norm(pixels - pixels[-1], axis=1)) > MARKER_CLEARANCE
    assert clear.sum() > 150
    found = matches(pixels_at(image, frame, path[clear]), PATH_COLOUR)
    assert found.all(), f"path colour missing at {path[clear][~found][:5]}"
    # The line is 3.5 pixels wide and nowhere steeper than 32 degrees: 5 rows below it is off it.
    columns, rows = np.floor(frame.to_pixels(path[clear])).astype(int).T
    assert not matches(image[rows + 5, columns], PATH_COLOUR).any()


def test_scan_points_are_drawn_where_they_are(drawing, scan_points):
    _, frame, image = drawing
    assert len(scan_points) > 100
    found = matches(pixels_at(image, frame, scan_points), SCAN_COLOUR)
    assert found.all(), f"scan colour missing at {scan_points[~found][:5]}"


def test_obstacle_is_filled_at_its_centre(drawing, world):
    _, frame, image = drawing
    barrier = next(shape for shape in world.shapes if shape.model == "jersey_barrier")
    centre = np.mean(np.asarray(footprint(barrier)), axis=0)
    assert matches(pixels_at(image, frame, [centre]), OBSTACLE_COLOUR).all()


def test_ground_is_not_an_obstacle(drawing):
    _, frame, image = drawing
    # The playground keeps x in [-1.5, 3.5], y in [-1.5, 1.5] clear; this point is off the path too.
    assert not matches(pixels_at(image, frame, [(1.0, -1.0)]), OBSTACLE_COLOUR).any()


def test_view_is_framed_on_the_run_not_on_the_ground_plane(drawing, run, scan_points):
    _, frame, _ = drawing
    everything = np.concatenate([run[0], scan_points])
    assert frame.xlim[0] < everything[:, 0].min() and everything[:, 0].max() < frame.xlim[1]
    assert frame.ylim[0] < everything[:, 1].min() and everything[:, 1].max() < frame.ylim[1]
    assert frame.xlim[1] - frame.xlim[0] < 2 * LIDAR_RANGE + 6.0
    assert frame.ylim[1] - frame.ylim[0] < 2 * LIDAR_RANGE + 6.0


def test_equal_aspect(drawing):
    _, frame, _ = drawing
    metres_per_column = (frame.xlim[1] - frame.xlim[0]) / (frame.right - frame.left)
    metres_per_row = (frame.ylim[1] - frame.ylim[0]) / (frame.bottom - frame.top)
    assert metres_per_column == pytest.approx(metres_per_row, rel=1e-3)


def test_frame_round_trips_through_json(drawing, tmp_path):
    _, frame, _ = drawing
    frame.save(str(tmp_path / "demo.json"))
    assert PlotFrame.load(str(tmp_path / "demo.json")) == frame


def test_an_empty_run_shows_the_world(world, tmp_path):
    frame = draw_demo(world, np.empty((0, 2)), np.empty((0, 2)), str(tmp_path / "empty.png"))
    assert (tmp_path / "empty.png").is_file()
    assert frame.xlim[0] < -4.0 and frame.xlim[1] > 5.6  # the cart behind, the barrier ahead
