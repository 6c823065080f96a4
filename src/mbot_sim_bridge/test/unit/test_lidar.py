"""core/sensors/lidar.py: <sensor> parsing and Gazebo-style scans of tiny PyBullet worlds (DIRECT, no master)."""
import logging
import math
from dataclasses import replace

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from mbot_sim_bridge.core.errors import ConfigError, ModelError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose, compose, pose_from_xyz_rpy
from mbot_sim_bridge.core.sensors.lidar import LaserScanner, RaySensorConfig, parse_ray_sensor
from mbot_sim_bridge.core.xml_values import parse_xml

# The tutorial's rplidar block, as lidar_gazebo.xacro expands it.
RPLIDAR = """
<gazebo reference="laser_link">
  <sensor type="ray" name="rplidar">
    <pose>0 0 0 0 0 0</pose>
    <visualize>false</visualize>
    <update_rate>5.5</update_rate>
    <ray>
      <scan>
        <horizontal>
          <samples>360</samples>
          <resolution>1</resolution>
          <min_angle>-3</min_angle>
          <max_angle>3</max_angle>
        </horizontal>
      </scan>
      <range>
        <min>0.10</min>
        <max>6.0</max>
        <resolution>0.01</resolution>
      </range>
      <noise>
        <type>gaussian</type>
        <mean>0.0</mean>
        <stddev>0.01</stddev>
      </noise>
    </ray>
    <plugin name="gazebo_rplidar" filename="libgazebo_ros_laser.so">
      <topicName>/scan</topicName>
      <frameName>laser_link</frameName>
    </plugin>
  </sensor>
</gazebo>
"""
SENSOR = "lidar 'rplidar' on link 'laser_link'"
MM = 0.005


def parse(xml: str = RPLIDAR) -> RaySensorConfig:
    document = parse_xml(xml.encode(), "test", ModelError)
    return parse_ray_sensor(document.root.find("sensor"), "laser_link", document)


def edited(old: str, new: str) -> str:
    assert old in RPLIDAR
    return RPLIDAR.replace(old, new)


def noiseless(**changes) -> RaySensorConfig:
    return replace(parse(), noise_mean=None, noise_stddev=None, **changes)


def full_circle(**changes) -> RaySensorConfig:
    """361 beams 1° apart over [-π, π]: beam 180 looks along +x, beam 270 along +y."""
    return replace(noiseless(samples=361, min_angle=-math.pi, max_angle=math.pi), **changes)


def beam_angles(config: RaySensorConfig) -> np.ndarray:
    return config.min_angle + np.arange(config.range_count) * config.angle_increment


def add_box(client, half_extents, pose: Pose = IDENTITY, mass: float = 0.0) -> int:
    shape = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half_extents)
    return client.createMultiBody(baseMass=mass, baseCollisionShapeIndex=shape,
                                  basePosition=pose.position, baseOrientation=pose.orientation)


def add_robot(client) -> int:
    """A plate under the sensor and a mast 0.45 m ahead of it on a fixed joint."""
    plate = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.2, 0.2, 0.02])
    mast = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.05, 0.05, 0.3])
    body = client.createMultiBody(
        baseMass=1.0, baseCollisionShapeIndex=plate, basePosition=[0, 0, -0.2],
        linkMasses=[0.1], linkCollisionShapeIndices=[mast], linkVisualShapeIndices=[-1],
        linkPositions=[[0.5, 0, 0.2]], linkOrientations=[[0, 0, 0, 1]],
        linkInertialFramePositions=[[0, 0, 0]], linkInertialFrameOrientations=[[0, 0, 0, 1]],
        linkParentIndices=[0], linkJointTypes=[pybullet.JOINT_FIXED], linkJointAxis=[[0, 0, 1]])
    return body


def scan(client, config, pose=IDENTITY, seed=0):
    return LaserScanner(client, config, np.random.default_rng(seed)).scan(pose).ranges


# --- parsing ---------------------------------------------------------------------------------------------

def test_parses_the_tutorial_rplidar():
    config = parse()
    assert (config.sensor_name, config.link) == ("rplidar", "laser_link")
    assert config.pose == IDENTITY
    assert config.update_rate == 5.5
    assert (config.samples, config.resolution, config.min_angle, config.max_angle) == (360, 1.0, -3.0, 3.0)
    assert (config.vertical_samples, config.vertical_min_angle, config.vertical_max_angle) == (1, 0.0, 0.0)
    assert (config.range_min, config.range_max) == (0.10, 6.0)
    assert (config.noise_mean, config.noise_stddev) == (0.0, 0.01)
    assert config.range_count == 360
    assert config.angle_increment == pytest.approx(6.0 / 359)


def test_range_count_and_angle_increment_follow_gazebo():
    assert noiseless(resolution=2.0).range_count == 720
    assert noiseless(resolution=2.0).angle_increment == pytest.approx(6.0 / 719)
    assert noiseless(samples=1).angle_increment == 0.0


def test_sensor_pose_and_vertical_scan():
    vertical = ("<vertical><samples>4</samples><min_angle>-0.2</min_angle>"
                "<max_angle>0.1</max_angle></vertical>")
    config = parse(edited("<pose>0 0 0 0 0 0</pose>", "<pose>0.1 0 0.2 0 0 1.5708</pose>")
                   .replace("</horizontal>", "</horizontal>" + vertical))
    assert config.pose.position == pytest.approx((0.1, 0.0, 0.2))
    assert config.pose == pytest.approx(pose_from_xyz_rpy((0.1, 0, 0.2), (0, 0, 1.5708)))
    assert (config.vertical_samples, config.vertical_resolution) == (4, 1.0)
    assert (config.vertical_min_angle, config.vertical_max_angle) == (-0.2, 0.1)


@pytest.mark.parametrize("old, new, message", [
    ("<samples>360</samples>", "<samples>abc</samples>",
     "<ray/scan/horizontal/samples> has bad value 'abc': expected a whole number, got 'abc'"),
    ("<samples>360</samples>", "<samples>0</samples>",
     "<ray/scan/horizontal/samples> has bad value '0': 0 is outside the valid range >= 1"),
    ("<resolution>1</resolution>", "<resolution>-1</resolution>",
     "<ray/scan/horizontal/resolution> has bad value '-1': -1 is outside the valid range > 0"),
    ("<min_angle>-3</min_angle>", "<min_angle>nan</min_angle>",
     "<ray/scan/horizontal/min_angle> has bad value 'nan': NaN is not a valid value"),
    ("<min_angle>-3</min_angle>", "<min_angle>4</min_angle>",
     "<min_angle> (4.0) must not exceed <max_angle> (3.0)"),
    ("<max>6.0</max>", "<max>0.05</max>", "<range><max> (0.05) must exceed <range><min> (0.1)"),
    ("<stddev>0.01</stddev>", "<stddev>-0.01</stddev>",
     "<ray/noise/stddev> has bad value '-0.01': -0.01 is outside the valid range >= 0"),
    ("<update_rate>5.5</update_rate>", "<update_rate>fast</update_rate>",
     "<update_rate> has bad value 'fast': expected a number, got 'fast'"),
    ("<pose>0 0 0 0 0 0</pose>", "<pose>0 0 0</pose>",
     "<pose> (x y z roll pitch yaw): expected 6 numbers, got '0 0 0'"),
    ("<pose>0 0 0 0 0 0</pose>", "<pose>nan 0 0 0 0 0</pose>",
     "<pose> (x y z roll pitch yaw): NaN is not a valid value: 'nan 0 0 0 0 0'"),
    ("<min>0.10</min>", "", "missing required tag <ray/range/min>"),
    ("horizontal>", "horizontl>", "missing required tag <ray/scan/horizontal/samples>"),
    ("<samples>360</samples>", "<samples>1</samples><resolution>0.5</resolution>", "leaves no ranges"),
    ('type="ray"', 'type="camera"', "type 'camera' is not a ray sensor"),
])
def test_bad_values_name_where_sensor_tag_value_and_range(old, new, message):
    with pytest.raises(ConfigError) as error:
        parse(edited(old, new))
    assert str(error.value).startswith("test:") and SENSOR in str(error.value)
    assert message in str(error.value)


def test_unnamed_sensor_is_an_error():
    with pytest.raises(ConfigError, match="a <sensor> on link 'laser_link' has no name"):
        parse(edited(' name="rplidar"', ""))


def test_non_gaussian_noise_warns_once_and_is_off(caplog):
    xml = edited("<type>gaussian</type>", "<type>uniform</type>")
    with caplog.at_level(logging.WARNING):
        config = parse(xml)
        parse(xml)
    assert (config.noise_mean, config.noise_stddev) == (None, None)
    assert len([r for r in caplog.records if "'uniform'" in r.getMessage()]) == 1


def test_noise_type_none_is_silent(caplog):
    config = parse(edited("<type>gaussian</type>", "<type>none</type>"))
    assert config.noise_stddev is None
    assert caplog.text == ""


# --- scanning --------------------------------------------------------------------------------------------

SENSOR_POSE = pose_from_xyz_rpy((1.0, -2.0, 0.3), (0.0, 0.0, 0.7))


@pytest.mark.parametrize("distance", [0.5, 2.0, 5.5])
def test_wall_at_known_distance(client, distance):
    config = noiseless()
    wall_in_sensor = pose_from_xyz_rpy((distance + 0.05, 0, 0), (0, 0, 0))
    add_box(client, [0.05, 20.0, 1.0], compose(SENSOR_POSE, wall_in_sensor))
    ranges = scan(client, config, SENSOR_POSE)
    angles = beam_angles(config)
    # Along a beam at angle a to the wall's normal the wall is d/cos(a) away; rays start at range_min.
    with np.errstate(divide="ignore"):
        expected = np.where(np.cos(angles) > 0, distance / np.cos(angles), np.inf)
    hits = expected < config.range_max - 0.01
    assert ranges.dtype == np.float32 and len(ranges) == 360
    assert hits.sum() > 40
    assert np.mean(ranges[hits] * np.cos(angles[hits])) == pytest.approx(distance, abs=MM)
    assert np.all(np.abs(ranges[hits] - expected[hits]) < MM)
    assert np.all(np.isposinf(ranges[expected > config.range_max + 0.01]))


def test_gaussian_noise_has_the_configured_spread(client):
    config = replace(parse(), noise_mean=0.0, noise_stddev=0.01)
    add_box(client, [0.05, 20.0, 1.0], pose_from_xyz_rpy((2.05, 0, 0), (0, 0, 0)))
    scanner = LaserScanner(client, config, np.random.default_rng(42))
    angles = beam_angles(config)
    hits = np.cos(angles) > 2.0 / 5.5
    errors = np.concatenate([scanner.scan(IDENTITY).ranges[hits] - 2.0 / np.cos(angles[hits])
                             for _ in range(20)])
    assert np.std(errors) == pytest.approx(0.01, rel=0.2)
    assert abs(np.mean(errors)) < 0.002


def test_nothing_in_range_reads_plus_inf(client):
    add_box(client, [0.5, 0.5, 0.5], pose_from_xyz_rpy((7.0, 0, 0), (0, 0, 0)))
    scanner = LaserScanner(client, parse(), np.random.default_rng(0))
    result = scanner.scan(IDENTITY)
    assert np.all(np.isposinf(result.ranges))
    assert result.intensities.dtype == np.float32 and not result.intensities.any()


def test_obstacle_closer_than_range_min_is_not_seen(client):
    """Rays start at range_min (0.1 m): a box 0.03–0.07 m ahead is missed and the wall behind it is seen."""
    add_box(client, [0.02, 0.02, 0.02], pose_from_xyz_rpy((0.05, 0, 0), (0, 0, 0)))
    add_box(client, [0.05, 1.0, 1.0], pose_from_xyz_rpy((3.05, 0, 0), (0, 0, 0)))
    assert scan(client, full_circle())[180] == pytest.approx(3.0, abs=MM)


def test_obstacle_around_the_ray_start_is_not_seen(client):
    """PyBullet ignores a convex shape around the ray start; Gazebo's ODE would read its far face (0.3)."""
    add_box(client, [0.125, 0.2, 0.2], pose_from_xyz_rpy((0.175, 0, 0), (0, 0, 0)))
    assert np.isposinf(scan(client, full_circle())[180])


def test_surface_at_range_min_reads_minus_inf(client):
    """A ray starting on a surface reports fraction 0, i.e. raw = range_min, which REP 117 masks as −inf."""
    add_box(client, [0.05, 0.01, 0.2], pose_from_xyz_rpy((0.15, 0, 0), (0, 0, 0)))
    ranges = scan(client, full_circle(noise_mean=0.0, noise_stddev=0.01))
    assert np.isneginf(ranges[180])


def test_beam_angles_run_counter_clockwise(client):
    config = full_circle()
    # Each box is seen by three beams: its centre beam and the beams 1° either side (2° misses).
    add_box(client, [0.03, 0.03, 0.2], pose_from_xyz_rpy((0, 1.0, 0), (0, 0, 0)))
    add_box(client, [0.05, 0.05, 0.2], pose_from_xyz_rpy((0, -2.0, 0), (0, 0, 0)))
    ranges = scan(client, config)
    left = round((math.pi / 2 - config.min_angle) / config.angle_increment)
    right = round((-math.pi / 2 - config.min_angle) / config.angle_increment)
    assert (left, right) == (270, 90)
    assert ranges[left] == pytest.approx(0.97, abs=MM)
    assert ranges[right] == pytest.approx(1.95, abs=MM)
    assert set(np.flatnonzero(np.isfinite(ranges))) == {89, 90, 91, 269, 270, 271}


def test_rays_see_the_robots_own_links_as_in_gazebo(client):
    add_robot(client)
    add_box(client, [0.05, 0.2, 0.2], pose_from_xyz_rpy((-1.55, 0, 0), (0, 0, 0)))
    ranges = scan(client, full_circle())
    assert ranges[180] == pytest.approx(0.45, abs=MM)  # the mast the sensor's robot carries
    assert ranges[0] == pytest.approx(1.5, abs=MM)


def test_same_seed_gives_identical_noisy_scans():
    def scans(seed):
        bullet = BulletClient(connection_mode=pybullet.DIRECT)
        add_box(bullet, [0.05, 20.0, 1.0], pose_from_xyz_rpy((2.05, 0, 0), (0, 0, 0)))
        add_box(bullet, [0.3, 0.3, 0.3], pose_from_xyz_rpy((-1.0, 1.0, 0), (0, 0, 0.4)))
        scanner = LaserScanner(bullet, parse(), np.random.default_rng(seed))
        result = [scanner.scan(SENSOR_POSE).ranges for _ in range(3)]
        bullet.disconnect()
        return np.array(result)

    first = scans(7)
    np.testing.assert_array_equal(first, scans(7))
    assert np.isfinite(first).sum() > 100
    assert not np.array_equal(first, scans(8))


def test_resolution_interpolates_raw_ranges_like_gazebo(client):
    """Two rays, four ranges: the outputs between a hit (1 m) and a miss (raw = range_max) are blended."""
    config = noiseless(samples=2, resolution=2.0, min_angle=0.0, max_angle=math.pi / 2)
    add_box(client, [0.05, 0.5, 0.5], pose_from_xyz_rpy((1.05, 0, 0), (0, 0, 0)))
    ranges = scan(client, config)
    assert config.angle_increment == pytest.approx(math.pi / 6)
    np.testing.assert_allclose(ranges, [1.0, 1.0 + 5.0 / 3, 1.0 + 10.0 / 3, np.inf], atol=MM)


def test_vertical_layers_are_row_major_lowest_first(client):
    config = noiseless(samples=3, min_angle=-0.1, max_angle=0.1,
                       vertical_samples=3, vertical_min_angle=-0.3, vertical_max_angle=0.3)
    sensor = pose_from_xyz_rpy((0, 0, 0.5), (0, 0, 0))
    add_box(client, [0.05, 1.0, 0.15], pose_from_xyz_rpy((1.05, 0, 0.15), (0, 0, 0)))   # seen only below
    add_box(client, [0.05, 1.0, 0.15], pose_from_xyz_rpy((2.05, 0, 1.25), (0, 0, 0)))   # seen only above
    ranges = scan(client, config, sensor).reshape(3, 3)
    np.testing.assert_allclose(ranges[0], 1.0 / math.cos(0.3) / np.cos([-0.1, 0.0, 0.1]), atol=MM)
    assert np.all(np.isposinf(ranges[1]))
    np.testing.assert_allclose(ranges[2], 2.0 / math.cos(0.3) / np.cos([-0.1, 0.0, 0.1]), atol=MM)


def test_scans_larger_than_one_pybullet_batch(client):
    config = noiseless(samples=1201, min_angle=-0.6, max_angle=0.6,
                       vertical_samples=15, vertical_min_angle=-0.1, vertical_max_angle=0.1)
    add_box(client, [0.05, 20.0, 20.0], pose_from_xyz_rpy((2.05, 0, 0), (0, 0, 0)))
    ranges = scan(client, config)
    assert len(ranges) == 1201 * 15 > pybullet.MAX_RAY_INTERSECTION_BATCH_SIZE
    pitch = np.linspace(-0.1, 0.1, 15)[:, np.newaxis]
    yaw = np.linspace(-0.6, 0.6, 1201)[np.newaxis, :]
    # The distance to the plane x = 2 along a ray with direction x component cos(p)·cos(y).
    np.testing.assert_allclose(ranges, (2.0 / (np.cos(pitch) * np.cos(yaw))).ravel(), atol=MM)
