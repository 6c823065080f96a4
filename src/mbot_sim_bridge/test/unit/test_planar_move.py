"""libgazebo_ros_planar_move.so (core/drives/planar_move.py) on mobile_test_robots' holonomic base: the base moves at
the commanded x, y and yaw rate within 1 %, odometry as upstream forms it, cmdTimeout, reset."""
import math

import pytest
from plugin_robots import HOLONOMIC_XACRO
from sensor_fixtures import expanded, plugin_of, world_simulation

from mbot_sim_bridge.core.geometry import Pose, pose_from_xyz_rpy, yaw
from mbot_sim_bridge.core.drives.planar_move import PlanarMove
from mbot_sim_bridge.core.description.robot_model import parse_robot


@pytest.fixture
def base(tmp_path):
    sim = world_simulation(tmp_path)
    urdf = expanded(HOLONOMIC_XACRO)
    # On the ground: planar move zeroes the vertical velocity every step, so a base spawned above it takes
    # seconds to sink down (in Gazebo too).
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'holonomic_base'"), "holonomic_base",
                              Pose((0.0, 0.0, -0.05), (0.0, 0.0, 0.0, 1.0)))
    sim.step(200)
    yield sim, spawned, plugin_of(spawned, PlanarMove)
    sim.close()


def body_motion(sim, spawned, plugin, command, seconds):
    """Mean robot-frame (vx, vy) and yaw rate over ``seconds`` of sim time, the command re-sent every 0.1 s."""
    start_pose, start_time = spawned.robot.root_pose(), sim.sim_time
    sums = [0.0, 0.0]
    steps = 0
    for _ in range(int(round(seconds / 0.1))):
        plugin.set_command(*command)
        for _ in range(100):
            sim.step(1)
            linear, _ = spawned.robot.root_velocity()
            heading = yaw(spawned.robot.root_pose().orientation)
            sums[0] += math.cos(heading) * linear[0] + math.sin(heading) * linear[1]
            sums[1] += math.cos(heading) * linear[1] - math.sin(heading) * linear[0]
            steps += 1
    turned = math.remainder(yaw(spawned.robot.root_pose().orientation) - yaw(start_pose.orientation), 2 * math.pi)
    return sums[0] / steps, sums[1] / steps, turned / (sim.sim_time - start_time)


@pytest.mark.parametrize("command", [(0.5, 0.0, 0.0), (0.0, -0.4, 0.0), (0.3, 0.2, 0.5), (0.0, 0.0, -1.0)])
def test_the_base_moves_as_commanded_within_1_percent(base, command):
    sim, spawned, plugin = base
    vx, vy, wz = body_motion(sim, spawned, plugin, command, 1.0)
    print(f"figure: planar move {command} -> ({vx:.4f}, {vy:.4f}, {wz:.4f})")
    for measured, wanted in zip((vx, vy, wz), command):
        assert measured == pytest.approx(wanted, rel=0.01, abs=0.002)


def test_the_chassis_friction_of_the_lumped_base_link_holds(base):
    """base_link is lumped into the base_footprint root; its <mu1>/<mu2> 0 stay on its collision, as in sdformat
    (with friction 1 the contact would take 1 % of the speed every step)."""
    _, spawned, _ = base
    robot = spawned.robot
    assert robot.client.getDynamicsInfo(robot.body, -1)[1] == 0.0
    assert len(robot.client.getContactPoints(robot.body)) > 0  # resting on the ground


def test_odometry_is_the_pose_and_its_difference(base):
    sim, spawned, plugin = base
    body_motion(sim, spawned, plugin, (0.4, 0.1, 0.2), 0.5)
    assert plugin.timer.period == pytest.approx(1 / 50)
    plugin.update(sim.sim_time)  # restart the difference from now
    body_motion(sim, spawned, plugin, (0.4, 0.1, 0.2), 0.1)
    plugin.update(sim.sim_time)
    odometry = plugin.latest
    assert odometry.linear == pytest.approx((0.4, 0.1), abs=0.01)
    assert odometry.angular == pytest.approx(0.2, abs=0.005)
    # The pose is the world's: the base put elsewhere is reported there at the next update (50 Hz: 20 steps).
    plugin.set_command(0.0, 0.0, 0.0)
    height = spawned.robot.root_pose().position[2]
    sim.engine.set_model_state("holonomic_base", pose_from_xyz_rpy((1.5, -0.8, height), (0, 0, 2.0)))
    sim.step(20)
    assert plugin.latest.pose.position[:2] == pytest.approx((1.5, -0.8), abs=1e-3)
    assert yaw(plugin.latest.pose.orientation) == pytest.approx(2.0, abs=1e-3)


def test_the_command_times_out_and_reset_stops_the_base(base):
    sim, spawned, plugin = base
    plugin.set_command(0.5, 0.0, 0.0)
    sim.step(400)
    assert spawned.robot.root_velocity()[0][0] == pytest.approx(0.5, abs=0.01)
    sim.step(200)  # cmdTimeout is 0.5 s
    assert abs(spawned.robot.root_velocity()[0][0]) < 0.01
    plugin.set_command(0.5, 0.0, 0.0)
    assert not plugin.set_command(math.nan, 0.0, 0.0)
    sim.step(50)
    sim.reset(simulation=False)
    sim.step(50)
    assert math.hypot(*spawned.robot.root_velocity()[0][:2]) < 0.01


@pytest.mark.parametrize("command", [(1e10, 0.0, 0.0), (0.0, -1e5, 0.0), (0.0, 0.0, 1e300)])
def test_a_command_beyond_set_model_states_cap_is_refused(base, command):
    """1e10 m/s sent the base 50 m backwards in one step; beyond 1e4 (set_model_state's cap) it is refused."""
    sim, spawned, plugin = base
    start = spawned.robot.root_pose().position
    assert not plugin.set_command(*command)
    sim.step(100)
    assert math.dist(spawned.robot.root_pose().position, start) < 1e-3
