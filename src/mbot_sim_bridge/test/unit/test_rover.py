"""The rover (rover_description, rover_control): a Husky-style base whose collision meshes are package:// STL and
COLLADA files, spawned from its xacro and driven through gazebo_ros_control and diff_drive_controller with its
own control.yaml, as its launch files do."""
import os

import pytest
from ros_control_fixtures import WORKSPACE_SRC, load_yaml, simulate, start_controllers
from sensor_fixtures import measured_motion

from mbot_sim_bridge.package_uris import resolve_package_uris
from mbot_sim_bridge.robot_description import expand_xacro

ROVER_XACRO = os.path.join(WORKSPACE_SRC, "rover_description", "urdf", "rover.urdf.xacro")
ROVER_CONTROL = os.path.join(WORKSPACE_SRC, "rover_control", "config", "control.yaml")


@pytest.fixture(scope="module")
def rover():
    urdf = expand_xacro(ROVER_XACRO, lidar_3d_enabled="false")
    assert "package://rover_description/meshes/chassis.stl" in urdf
    assert "package://rover_description/meshes/top_plate.dae" in urdf
    sim, spawned, plugin = simulate(urdf, load_yaml(ROVER_CONTROL), "rover", package_uris=resolve_package_uris,
                                    namespace="/")
    controller = start_controllers(sim, plugin, "rover_velocity_controller", "rover_joint_publisher")
    # Spawned at z = 0 as Husky's launch spawns Husky, the wheels start 13 cm into the ground; the rover rises onto
    # them within 0.04 s (test_penetration.py) and the rest of the 3 s lets it settle on them.
    sim.step(3000)
    yield sim, spawned, plugin, controller
    sim.close()


def test_the_rover_spawned_at_the_ground_rests_on_its_wheels(rover):
    sim, spawned, _, _ = rover
    # base_link sits at the axle height above the ground: wheel radius minus the wheels' vertical offset.
    assert spawned.robot.root_pose().position[2] == pytest.approx(0.1651 - 0.03282, abs=0.005)


@pytest.mark.parametrize("linear", [0.5, -0.3])
def test_the_mesh_rover_drives_straight_within_5_percent(rover, linear):
    sim, spawned, _, controller = rover
    speed, yaw_rate = measured_motion(sim, spawned, lambda: controller.set_command(linear, 0.0, sim.sim_time))
    print(f"figure: rover through diff_drive_controller: {linear} m/s commanded -> {speed:.3f} m/s")
    assert speed == pytest.approx(linear, rel=0.05)
    assert abs(yaw_rate) < 0.01


@pytest.mark.parametrize("angular", [0.8, -0.8])
def test_the_mesh_rover_turns_in_place_the_commanded_way(rover, angular):
    """Skid steering turns by sliding the wheels sideways, so the rate depends on friction and on the tuned
    wheel_separation_multiplier (the README's "What differs from Gazebo" gives the measured spread)."""
    sim, spawned, _, controller = rover
    speed, yaw_rate = measured_motion(sim, spawned, lambda: controller.set_command(0.0, angular, sim.sim_time))
    print(f"figure: rover through diff_drive_controller: {angular} rad/s commanded -> {yaw_rate:.3f} rad/s")
    assert yaw_rate == pytest.approx(angular, rel=0.25)
    assert abs(speed) < 0.02
