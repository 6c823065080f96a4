"""The demo's camera frame: what the course's kinect sees from a pose, drawn beside the top view without
moving the top view."""
import os

import numpy as np
from PIL import Image

from mbot_gazebo.demo import camera_frame
from mbot_gazebo.demo_plot import IMAGE_SIZE, draw_demo
from mbot_sim_bridge.core.description.sdf_world import parse_world

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
PLAYGROUND = os.path.join(REPO, "worlds", "playground.world")


def test_the_kinect_frame_sees_the_barrier_ahead(tmp_path):
    # From the origin facing +x the jersey barrier (near face at x = 5) fills the middle of the picture.
    image = camera_frame(PLAYGROUND, 0.0, 0.0, 0.0, str(tmp_path / "kinect.log"))
    assert "[DEBUG]" in (tmp_path / "kinect.log").read_text(), "the plugins' logs (rosDebugLevel Debug) go there"
    assert image.shape == (480, 640, 3) and image.dtype == np.uint8
    sky = np.all(image == (178, 178, 178), axis=2)
    colours = len(np.unique(image.reshape(-1, 3), axis=0))
    print(f"figure: demo camera frame: {100 * sky.mean():.0f} % sky, {colours} distinct colours")
    assert 0.2 < sky[:240].mean() < 1.0  # sky above the horizon, with the barrier in it
    assert not sky[300:].any()  # the ground below


def test_the_camera_picture_sits_beside_an_unmoved_top_view(tmp_path):
    world = parse_world(PLAYGROUND)
    path = np.array([[0.0, 0.0], [1.0, 0.2], [2.0, 0.5]])
    red = np.zeros((480, 640, 3), dtype=np.uint8)
    red[..., 0] = 255
    plain = draw_demo(world, path, np.zeros((0, 2)), str(tmp_path / "plain.png"))
    framed = draw_demo(world, path, np.zeros((0, 2)), str(tmp_path / "camera.png"), camera_image=red,
                       camera_caption="kinect")
    assert framed == plain
    pixels = np.asarray(Image.open(tmp_path / "camera.png").convert("RGB")).astype(int)
    assert pixels.shape[:2] == (IMAGE_SIZE[1], IMAGE_SIZE[0])
    is_red = (pixels[..., 0] > 200) & (pixels[..., 1] < 50) & (pixels[..., 2] < 50)
    columns = np.flatnonzero(is_red.any(axis=0))
    assert is_red.sum() > 20000 and columns.min() > plain.right
