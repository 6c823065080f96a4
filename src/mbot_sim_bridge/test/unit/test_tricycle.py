"""libgazebo_ros_tricycle_drive.so (core/drives/tricycle_drive.py) on mobile_test_robots' tricycle: cmd_vel's linear.x
is the front wheel's speed and angular.z the steering angle, as upstream reads them; in steady state the base moves as a
tricycle's kinematics say within 5 %, both ways round, forwards and backwards; encoder odometry keeps the
distance within 5 % (and upstream's heading sign); bad joints are refused, NaN ignored, reset stops it."""
import math

import pytest
from plugin_robots import TRICYCLE_XACRO
from sensor_fixtures import expanded, measured_motion, plugin_of, world_simulation

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, yaw
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.drives.tricycle_drive import TricycleDrive

WHEELBASE = 0.5
ON_ITS_WHEELS = pose_from_xyz_rpy((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def urdf(odometry_source="world"):
    return expanded(TRICYCLE_XACRO, odometry_source=odometry_source)


def spawn(tmp_path, text):
    sim = world_simulation(tmp_path)
    spawned = sim.spawn_robot(parse_robot(text, "model 'tricycle'"), "tricycle", ON_ITS_WHEELS)
    sim.step(300)
    return sim, spawned, plugin_of(spawned, TricycleDrive)


@pytest.fixture(scope="module")
def tricycle(tmp_path_factory):
    sim, spawned, plugin = spawn(tmp_path_factory.mktemp("tricycle"), urdf())
    yield sim, spawned, plugin
    sim.close()


@pytest.mark.parametrize("speed, angle", [(0.5, 0.0), (-0.3, 0.0), (0.5, 0.4), (0.5, -0.4), (-0.3, 0.4)])
def test_the_base_moves_as_a_tricycle_within_5_percent(tricycle, speed, angle):
    sim, spawned, plugin = tricycle
    forward, yaw_rate = measured_motion(sim, spawned, lambda: plugin.set_command(speed, angle))
    # The front wheel rolls at `speed` along its own heading; the rear axle follows.
    expected_forward, expected_yaw_rate = speed * math.cos(angle), speed * math.sin(angle) / WHEELBASE
    (steering, _, _), = spawned.robot.joint_state(["front_steering_joint"])
    print(f"figure: tricycle ({speed} m/s, steering {angle} rad): {forward:.4f} m/s for {expected_forward:.4f}, "
          f"{yaw_rate:.4f} rad/s for {expected_yaw_rate:.4f}, steering at {steering:.4f} rad")
    assert steering == pytest.approx(angle, abs=0.005)
    assert forward == pytest.approx(expected_forward, rel=0.05)
    assert yaw_rate == pytest.approx(expected_yaw_rate, rel=0.05, abs=0.005)


def test_world_odometry_is_the_ground_truth(tricycle):
    sim, spawned, plugin = tricycle
    measured_motion(sim, spawned, lambda: plugin.set_command(0.4, 0.2), settle=1.0, window=0.2)
    sim.step(20)  # one update at 50 Hz
    odometry = plugin.latest
    assert odometry.linear[0] == pytest.approx(0.4 * math.cos(0.2), rel=0.05)
    assert odometry.angular == pytest.approx(0.4 * math.sin(0.2) / WHEELBASE, rel=0.05)


def test_world_odometry_reports_where_the_model_is_put(tmp_path):
    sim, spawned, plugin = spawn(tmp_path, urdf())
    plugin.set_command(0.0, 0.0)
    height = spawned.robot.root_pose().position[2]
    sim.engine.set_model_state("tricycle", pose_from_xyz_rpy((1.5, -0.8, height), (0, 0, 2.0)))
    sim.step(20)  # one update at 50 Hz
    assert plugin.latest.pose.position[:2] == pytest.approx((1.5, -0.8), abs=1e-3)
    assert yaw(plugin.latest.pose.orientation) == pytest.approx(2.0, abs=1e-3)


def test_encoder_odometry_keeps_the_distance_and_upstreams_heading_sign(tmp_path):
    sim, spawned, plugin = spawn(tmp_path, urdf("encoder"))
    start = spawned.robot.root_pose().position
    plugin.set_command(0.5, 0.0)
    sim.step(3000)
    end = spawned.robot.root_pose().position
    driven = math.hypot(end[0] - start[0], end[1] - start[1])
    x, y, _ = plugin.encoder_pose
    print(f"figure: tricycle encoder odometry: {math.hypot(x, y):.4f} m for {driven:.4f} m driven")
    assert math.hypot(x, y) == pytest.approx(driven, rel=0.05)
    plugin.set_command(0.5, 0.4)  # a left turn: upstream's (left - right) / separation goes negative
    sim.step(2000)
    assert yaw(spawned.robot.root_pose().orientation) > 0.5
    assert plugin.encoder_pose[2] < -0.5
    sim.close()


def test_a_steering_joint_the_robot_lacks_is_refused(tmp_path):
    sim = world_simulation(tmp_path)
    text = urdf().replace("<steeringJoint>front_steering_joint</steeringJoint>",
                          "<steeringJoint>front_fork_joint</steeringJoint>")
    with pytest.raises(ConfigError, match="<steeringJoint> names joint 'front_fork_joint'"):
        sim.spawn_robot(parse_robot(text, "model 'tricycle'"), "tricycle", ON_ITS_WHEELS)
    sim.close()


@pytest.mark.parametrize("joint, message", [
    ("laser_joint", "<steeringJoint> names joint 'laser_joint', which is fixed; movable joints:"),
    ("front_wheel_joint", "<steeringJoint> and <actuatedWheelJoint> both name joint 'front_wheel_joint'; each needs "
                          "a joint of its own"),
])
def test_a_steering_joint_that_cannot_steer_is_refused(tmp_path, joint, message):
    sim = world_simulation(tmp_path)
    try:
        text = urdf().replace("<steeringJoint>front_steering_joint</steeringJoint>",
                              f"<steeringJoint>{joint}</steeringJoint>")
        with pytest.raises(ConfigError, match=message):
            sim.spawn_robot(parse_robot(text, "model 'tricycle'"), "tricycle", ON_ITS_WHEELS)
        assert "tricycle" not in sim.model_names()
    finally:
        sim.close()


def test_nan_is_ignored_and_reset_stops_it(tmp_path):
    sim, spawned, plugin = spawn(tmp_path, urdf())
    assert plugin.set_command(0.4, 0.1)
    assert not plugin.set_command(math.nan, 0.0)
    assert not plugin.set_command(0.1, math.inf)
    assert plugin.command() == (0.4, 0.1)
    sim.step(500)
    sim.reset(simulation=False)
    sim.step(1000)
    assert math.hypot(*spawned.robot.root_velocity()[0][:2]) < 0.01
    sim.close()
