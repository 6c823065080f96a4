"""Velodyne's lidar plugins (core/sensors/velodyne_laser.py) on the VLP-16-style macro of mobile_test_robots: 16 rings
in the driver's order, points on a wall where it stands, range limits, organised clouds, the PointCloud2 layout."""
import os
import re

import numpy as np
import pytest
from plugin_robots import MOBILE_TEST_ROBOTS, VELODYNE_STAND
from sensor_fixtures import box, plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.sensors.velodyne_laser import VelodyneLaser
from mbot_sim_bridge.robot_description import expand_xacro

WALL_X = 3.0
# The scan frame: 0.5 m mount plus 37.7 mm.
SENSOR_Z = 0.5377


def velodyne(tmp_path, noise=0.0, organize=False):
    path = tmp_path / "stand.urdf.xacro"
    macro = os.path.abspath(os.path.join(MOBILE_TEST_ROBOTS, "urdf", "VLP-16.urdf.xacro"))
    path.write_text(VELODYNE_STAND.format(macro=macro, noise=noise, organize=str(organize).lower()))
    sim = world_simulation(tmp_path, box("wall", (WALL_X + 0.05, 0.0, 1.5), (0.1, 20.0, 3.0)))
    urdf = expand_xacro(str(path))
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'stand'"), "stand", Pose((0.0, 0.0, 0.0), (0, 0, 0, 1)))
    sim.step(10)
    return sim, plugin_of(spawned, VelodyneLaser)


@pytest.mark.parametrize("tags, message", [
    ({"min_range": "10", "max_range": "1"}, r"readings are kept between <min_range> 10 .* and <max_range> 1 .*: "
                                            r"none would be$"),
    ({"max_range": "0"}, r"<max_range> has bad value '0': 0 is outside the valid range > 0$"),
])
def test_a_range_window_that_keeps_nothing_is_refused(tmp_path, tags, message):
    path = tmp_path / "stand.urdf.xacro"
    macro = os.path.abspath(os.path.join(MOBILE_TEST_ROBOTS, "urdf", "VLP-16.urdf.xacro"))
    path.write_text(VELODYNE_STAND.format(macro=macro, noise=0.0, organize="false"))
    urdf = expand_xacro(str(path))
    for tag, text in tags.items():
        urdf, replaced = re.subn(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{text}</{tag}>", urdf)
        assert replaced == 1
    sim = world_simulation(tmp_path)
    try:
        with pytest.raises(ConfigError, match=message):
            sim.spawn_robot(parse_robot(urdf, "model 'stand'"), "stand")
        assert "stand" not in sim.model_names()
    finally:
        sim.close()


def test_sixteen_rings_lowest_first_and_points_on_the_wall(tmp_path):
    _, lidar = velodyne(tmp_path)
    cloud = lidar.cloud()
    assert sorted(set(cloud.ring.tolist())) == list(range(16))
    ahead = (np.abs(np.arctan2(cloud.xyz[:, 1], cloud.xyz[:, 0])) < 0.5) & (cloud.xyz[:, 2] + SENSOR_Z > 0.02)
    wall = cloud.xyz[ahead]
    error = np.abs(wall[:, 0] - WALL_X).max()
    print(f"figure: VLP-16-style lidar: {len(cloud.ring)} points, 16 rings; {len(wall)} on the wall 3 m ahead "
          f"within {error * 100:.2f} cm")
    assert len(wall) > 500 and error < 0.02
    lowest = cloud.xyz[cloud.ring == 0]
    assert np.all(lowest[:, 2] < 0)  # ring 0 looks 15 degrees down
    # Ring j's points lie on its cone: pitch = -15 + 2j degrees.
    pitch = np.degrees(np.arctan2(cloud.xyz[:, 2], np.hypot(cloud.xyz[:, 0], cloud.xyz[:, 1])))
    assert pitch == pytest.approx(-15.0 + 2.0 * cloud.ring, abs=0.01)


def test_readings_beyond_the_limits_are_dropped_or_nan_when_organised(tmp_path):
    _, lidar = velodyne(tmp_path)
    dense = lidar.cloud()
    assert not dense.organized and np.all(np.isfinite(dense.xyz))
    ranges = np.linalg.norm(dense.xyz, axis=1)
    assert ranges.min() > 0.9 and ranges.max() < 130.0
    _, organised_lidar = velodyne(tmp_path, organize=True)
    organised = organised_lidar.cloud()
    assert organised.organized and len(organised.ring) == 16 * 440 and organised.rows == 440
    # Listed column by column, as the driver lists them: each row is one direction, rings 0..15.
    assert organised.ring[:32].tolist() == list(range(16)) * 2
    # The upper rings see nothing beyond the wall's top in some directions: NaN there, and the same
    # valid points as the dense cloud.
    assert np.isnan(organised.xyz).any()
    assert np.count_nonzero(np.isfinite(organised.xyz[:, 0])) == len(dense.ring)


def test_noise_is_added_to_the_range_and_reruns_identically(tmp_path):
    _, lidar = velodyne(tmp_path, noise=0.01)
    _, again = velodyne(tmp_path, noise=0.01)
    first, second = lidar.cloud(), again.cloud()
    assert np.array_equal(first.xyz, second.xyz)
    ahead = np.abs(first.xyz[:, 1]) < 0.3
    spread = (first.xyz[ahead, 0] - WALL_X)[first.xyz[ahead, 2] > -SENSOR_Z + 0.05]
    assert np.std(spread) == pytest.approx(0.01, rel=0.3)


def test_the_pointcloud2_layout_is_velodyne_pointclouds():
    from mbot_sim_bridge.plugins.gazebo_ros_velodyne_laser import FIELDS, POINT
    assert [(f.name, f.offset, f.datatype) for f in FIELDS] == [
        ("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 12, 7), ("ring", 16, 4), ("time", 18, 7)]
    assert POINT.itemsize == 22
    # A point packed as the plugin packs it reads back through sensor_msgs' own reader of those fields.
    from sensor_msgs import point_cloud2
    from sensor_msgs.msg import PointCloud2
    point = np.zeros(1, POINT)
    point["x"], point["y"], point["z"], point["intensity"], point["ring"], point["time"] = 1.5, -2.25, 0.125, 7, 13, 0.5
    message = PointCloud2(height=1, width=1, fields=FIELDS, is_bigendian=False, point_step=POINT.itemsize,
                          row_step=POINT.itemsize, data=point.tobytes(), is_dense=True)
    assert list(point_cloud2.read_points(message)) == [(1.5, -2.25, 0.125, 7.0, 13, 0.5)]
