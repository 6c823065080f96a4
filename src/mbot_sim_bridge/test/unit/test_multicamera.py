"""libgazebo_ros_multicamera.so (core/cameras/multicamera.py) on mobile_test_robots' stereo head: a world point's
disparity between the rendered left and right images is fx·baseline/depth within 1 px; the right camera's P carries
Tx = −fx·hackBaseline and the left's 0; a camera named neither left nor right is said once; no usable camera is
refused."""
import math

import numpy as np
import pytest
from plugin_robots import STEREO_XACRO
from sensor_fixtures import box, expanded, plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.cameras.multicamera import MultiCamera
from mbot_sim_bridge.core.description.robot_model import parse_robot

BASELINE, HEAD_HEIGHT, WIDTH, HFOV = 0.07, 1.0, 320, 1.047
AT_ORIGIN = Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def urdf():
    return expanded(STEREO_XACRO, width=str(WIDTH))


def red_columns(rgb: np.ndarray) -> np.ndarray:
    red = (rgb[..., 0] > 150) & (rgb[..., 1] < 80) & (rgb[..., 2] < 80)
    return np.nonzero(red)[1]


@pytest.mark.parametrize("depth", [1.5, 3.0])
def test_disparity_of_a_world_point_is_fx_baseline_over_depth_within_1_px(tmp_path, depth):
    # A thin red plate facing the head, its face `depth` ahead of the cameras, between their optical axes.
    plate = box("target", (depth + 0.005, BASELINE / 2, HEAD_HEIGHT), (0.01, 0.2, 0.2), rgb=(1.0, 0.0, 0.0))
    sim = world_simulation(tmp_path, plate)
    spawned = sim.spawn_robot(parse_robot(urdf(), "model 'stereo_head'"), "stereo_head", AT_ORIGIN)
    sim.step(10)
    stereo = plugin_of(spawned, MultiCamera)
    left, right = (stereo.capture(side, sim.sim_time).rgb for side in ("left", "right"))
    fx = stereo.cameras["left"].intrinsics.f
    disparity = red_columns(left).mean() - red_columns(right).mean()
    expected = fx * BASELINE / depth
    print(f"figure: stereo head, plate {depth} m ahead: disparity {disparity:.2f} px for fx·b/z = {expected:.2f} px")
    assert fx == pytest.approx(WIDTH / (2 * math.tan(HFOV / 2)))
    assert disparity == pytest.approx(expected, abs=1.0)
    sim.close()


def test_the_right_camera_info_carries_the_baseline(tmp_path):
    sim = world_simulation(tmp_path)
    stereo = plugin_of(sim.spawn_robot(parse_robot(urdf(), "model 'stereo_head'"), "stereo_head", AT_ORIGIN),
                       MultiCamera)
    left, right = stereo.cameras["left"].intrinsics, stereo.cameras["right"].intrinsics
    assert left.P[3] == 0.0
    assert right.P[3] == pytest.approx(-right.f * BASELINE)
    # The right camera sits `baseline` to the left one's right (−y of the head).
    offset = np.subtract(stereo.camera_pose("right").position, stereo.camera_pose("left").position)
    assert offset == pytest.approx((0.0, -BASELINE, 0.0), abs=1e-6)
    sim.close()


def test_a_camera_named_neither_left_nor_right_is_said_once(tmp_path, caplog):
    sim = world_simulation(tmp_path)
    text = urdf().replace('<camera name="right">', '<camera name="middle">')
    stereo = plugin_of(sim.spawn_robot(parse_robot(text, "model 'stereo_head'"), "stereo_head", AT_ORIGIN),
                       MultiCamera)
    assert list(stereo.cameras) == ["left"]
    assert "camera 'middle' is not published" in caplog.text
    sim.close()


def test_a_sensor_without_a_left_or_right_camera_is_refused(tmp_path):
    sim = world_simulation(tmp_path)
    text = urdf().replace('<camera name="right">', '<camera name="b">').replace('<camera name="left">',
                                                                                '<camera name="a">')
    with pytest.raises(ConfigError, match="no <camera> named with 'left' or 'right'"):
        sim.spawn_robot(parse_robot(text, "model 'stereo_head'"), "stereo_head", AT_ORIGIN)
    sim.close()
