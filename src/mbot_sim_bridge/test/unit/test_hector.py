"""hector_gazebo_plugins' IMU, GPS and magnetometer (core/hector/hector_imu.py, hector_gps.py, hector_magnetic.py):
gravity up at rest, the turn rate, the fix moving north or east by the distance travelled as upstream converts
it, the field turning with the body, the sensor model."""
import math

import numpy as np
import pytest
from plugin_robots import HECTOR_ROBOT
from sensor_fixtures import plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import Pose, pose_from_xyz_rpy
from mbot_sim_bridge.core.hector.hector_gps import HectorGps, earth_radii
from mbot_sim_bridge.core.hector.hector_imu import HectorImu
from mbot_sim_bridge.core.hector.hector_magnetic import HectorMagnetic
from mbot_sim_bridge.core.hector.hector_sensor_model import SensorModel
from mbot_sim_bridge.core.description.robot_model import parse_robot


NOISY_IMU = """
      <accelGaussianNoise>0.05 0.05 0.05</accelGaussianNoise><rateGaussianNoise>0.01 0.01 0.01</rateGaussianNoise>
      <accelDrift>0.005 0.005 0.005</accelDrift><rateDrift>0.005 0.005 0.005</rateDrift>
      <yawDrift>0.005</yawDrift><yawGaussianNoise>0.005</yawGaussianNoise>"""


def spawn_box(tmp_path, heading=0.0, imu="", gps="", pose=Pose((0.0, 0.0, 0.1), (0.0, 0.0, 0.0, 1.0)), seed=0):
    sim = world_simulation(tmp_path, seed=seed)
    urdf = HECTOR_ROBOT.format(heading=heading, imu=imu, gps=gps)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'box'"), "box", pose)
    return sim, spawned


def simulate(tmp_path, **options):
    sim, spawned = spawn_box(tmp_path, **options)
    return sim, plugin_of(spawned, HectorImu), plugin_of(spawned, HectorGps)


def readings(sim, plugin, seconds):
    """The plugin's readings at its rate for ``seconds`` of sim time."""
    collected = []
    for _ in range(int(round(seconds / plugin.timer.period))):
        sim.step(int(round(plugin.timer.period / sim.step_size)))
        collected.append(plugin.latest)
    return collected


def test_the_imu_reads_gravity_up_at_rest_within_its_noise(tmp_path):
    sim, imu, _ = simulate(tmp_path, imu=NOISY_IMU)
    sim.step(500)  # settled on the ground
    samples = np.array([reading.linear_acceleration for reading in readings(sim, imu, 2.0)])
    mean = samples.mean(axis=0)
    print(f"figure: hector IMU at rest: mean a = ({mean[0]:.3f}, {mean[1]:.3f}, {mean[2]:.3f}) m/s², "
          f"stddev {samples.std(axis=0).round(3).tolist()}")
    # 200 samples of 0.05 noise: the mean is within 0.015 of the truth plus the drifting bias (0.005 stddev).
    assert mean == pytest.approx([0.0, 0.0, 9.8], abs=0.03)
    assert samples.std(axis=0) == pytest.approx([0.05] * 3, rel=0.2)
    assert imu.latest.linear_acceleration_covariance == pytest.approx((0.0025,) * 3)
    assert imu.frame_id == "imu_link"


def test_the_imu_reads_the_turn_rate(tmp_path):
    sim, imu, _ = simulate(tmp_path, pose=Pose((0.0, 0.0, 50.0), (0.0, 0.0, 0.0, 1.0)))
    sim.set_model_state("box", Pose((0.0, 0.0, 50.0), (0.0, 0.0, 0.0, 1.0)), angular=(0.0, 0.0, 0.5))
    reading = readings(sim, imu, 0.5)[-1]
    # PyBullet damps a free body's spin a little; the reading is the mean rate over the last 10 ms.
    truth = imu.context.robot.root_velocity()[1][2]
    print(f"figure: hector IMU spinning in the air: rate {reading.angular_velocity[2]:.4f} rad/s, "
          f"body {truth:.4f} rad/s")
    assert reading.angular_velocity == pytest.approx((0.0, 0.0, truth), abs=1e-3)
    heading = 2 * math.atan2(reading.orientation[2], reading.orientation[3])
    # 0.5 s at 0.5 rad/s is 0.25 rad, less what the damping took (the rate read above is its measure): the
    # reading's heading is the body's.
    orientation = imu.context.robot.root_pose().orientation  # a turn about z only
    body = 2 * math.atan2(orientation[2], orientation[3])
    assert 0.5 * truth <= body <= 0.25
    assert heading == pytest.approx(body, abs=0.01)


@pytest.mark.parametrize("heading, north, west", [(0.0, 1.0, 0.0), (90.0, 0.0, -1.0), (30.0, math.cos(math.radians(30)),
                                                                                      -math.sin(math.radians(30)))])
def test_the_fix_moves_by_the_distance_travelled_in_upstreams_directions(tmp_path, heading, north, west):
    """referenceHeading ψ is clockwise from north: at 0 the world's x points north (and y west); at 90, east."""
    start = Pose((0.0, 0.0, 50.0), (0.0, 0.0, 0.0, 1.0))
    sim, _, gps = simulate(tmp_path, heading=heading, pose=start)
    radius_north, radius_east = earth_radii(49.9)
    sim.set_model_state("box", start, linear=(1.0, 0.0, 0.0))
    sim.step(1)
    gps.update(sim.sim_time)
    first, x0 = gps.latest, gps.context.robot.link_world_pose("base_link").position[0]
    sim.step(2000)
    gps.update(sim.sim_time)
    last, x1 = gps.latest, gps.context.robot.link_world_pose("base_link").position[0]
    travelled = x1 - x0
    moved_north = math.radians(last.latitude - first.latitude) * radius_north
    moved_west = -math.radians(last.longitude - first.longitude) * radius_east
    print(f"figure: hector GPS, heading {heading:g} deg: {travelled:.4f} m along x -> {moved_north:.4f} m north, "
          f"{moved_west:.4f} m west")
    assert moved_north == pytest.approx(north * travelled, abs=0.01 * travelled)
    assert moved_west == pytest.approx(west * travelled, abs=0.01 * travelled)
    speed = gps.context.robot.root_velocity()[0][0]
    assert last.velocity[:2] == pytest.approx((north * speed, west * speed), abs=1e-3)


def test_the_fix_at_the_spawn_point_is_the_reference(tmp_path):
    sim, _, gps = simulate(tmp_path, pose=Pose((0.0, 0.0, 2.0), (0.0, 0.0, 0.0, 1.0)))
    gps.update(sim.sim_time)
    assert (gps.latest.latitude, gps.latest.longitude, gps.latest.altitude) == pytest.approx((49.9, 8.9, 102.0))
    assert gps.timer.period == pytest.approx(1 / 40)


def test_the_longitude_stays_a_longitude_at_the_pole(tmp_path):
    sim = world_simulation(tmp_path)
    try:
        urdf = HECTOR_ROBOT.format(heading=0.0, imu="", gps="").replace("<referenceLatitude>49.9<",
                                                                        "<referenceLatitude>90<")
        gps = plugin_of(sim.spawn_robot(parse_robot(urdf, "model 'box'"), "box"), HectorGps)
        latitude, longitude, _ = gps.geodetic((0.0, 1.0, 0.0))
        assert latitude == 90.0 and -180.0 <= longitude < 180.0  # was -8,496,471 degrees a metre from the pole
        assert gps.geodetic((0.0, 0.0, 0.0))[1] == pytest.approx(8.9)
    finally:
        sim.close()


def test_the_drift_is_a_gauss_markov_process_that_reruns_identically():
    model = SensorModel(0.1, 0.5, 1.0, 0.0, 1.0, np.random.default_rng(3))
    again = SensorModel(0.1, 0.5, 1.0, 0.0, 1.0, np.random.default_rng(3))
    values = [float(model(2.0, 0.01)) for _ in range(20000)]
    assert values == [float(again(2.0, 0.01)) for _ in range(20000)]
    # Upstream steps the drift by dt·N(0, sqrt(2f)·Drift), so once the drawn start has decayed (time constant
    # 1/f = 1 s) its stddev is Drift·sqrt(dt) (0.05 here), not Drift; the offset adds on.
    settled = values[10000:]
    assert np.std(settled) == pytest.approx(0.5 * math.sqrt(0.01), rel=0.2)
    assert np.mean(settled) == pytest.approx(2.1, abs=0.05)


def test_a_vector_tag_needs_three_numbers_and_noise_cannot_be_negative(tmp_path):
    with pytest.raises(ConfigError, match="<accelDrift> has bad value '0.1 0.2'"):
        simulate(tmp_path, imu="<accelDrift>0.1 0.2</accelDrift>")
    with pytest.raises(ConfigError, match="<velocityGaussianNoise> has bad value '-1 0 0': must be >= 0"):
        simulate(tmp_path, gps="<velocityGaussianNoise>-1 0 0</velocityGaussianNoise>")


def test_rpy_offset_rotates_the_orientation_and_the_rates(tmp_path):
    pose = pose_from_xyz_rpy((0.0, 0.0, 50.0), (0.0, 0.0, 0.0))
    sim, imu, _ = simulate(tmp_path, imu="<rpyOffset>0 0 1.5707963</rpyOffset>", pose=pose)
    sim.set_model_state("box", pose, angular=(0.5, 0.0, 0.0))
    reading = readings(sim, imu, 0.02)[-1]
    yaw = 2 * math.atan2(reading.orientation[2], reading.orientation[3])
    assert yaw == pytest.approx(math.pi / 2, abs=0.01)
    # A roll rate in the body frame is seen along -y by the IMU rotated 90 degrees about z.
    assert reading.angular_velocity == pytest.approx((0.0, -0.5, 0.0), abs=2e-3)


@pytest.mark.parametrize("yaw", [0.0, math.pi / 2])
def test_the_magnetic_field_turns_with_the_body_as_upstream_sets_it(tmp_path, yaw):
    """World field (m·cos ι·cos(ψ − δ), m·cos ι·sin(ψ − δ), −m·sin ι) with ψ = 0, δ = 10°, ι = 60°, m = 0.5,
    read in the body frame."""
    pose = pose_from_xyz_rpy((0.0, 0.0, 0.1), (0.0, 0.0, yaw))
    sim, spawned = spawn_box(tmp_path, pose=pose)
    magnetometer = plugin_of(spawned, HectorMagnetic)
    sim.step(20)
    magnetometer.update(sim.sim_time)
    horizontal = 0.5 * math.cos(math.radians(60))
    world = (horizontal * math.cos(math.radians(-10)), horizontal * math.sin(math.radians(-10)),
             -0.5 * math.sin(math.radians(60)))
    expected = (math.cos(yaw) * world[0] + math.sin(yaw) * world[1],
                -math.sin(yaw) * world[0] + math.cos(yaw) * world[1], world[2])
    field = tuple(round(value, 4) for value in magnetometer.latest.field)
    print(f"figure: hector magnetometer at yaw {math.degrees(yaw):.0f} deg: {field}")
    assert magnetometer.latest.field == pytest.approx(expected, abs=1e-3)
