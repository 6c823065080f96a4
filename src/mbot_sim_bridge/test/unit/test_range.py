"""Range finders on a ray sensor (core/sensors/range_sensor.py): libgazebo_ros_range.so and hector's sonar read a wall
at a known distance within 1 cm, max_range when clear, their field of view and noise as upstream."""
import numpy as np
import pytest
from plugin_robots import HECTOR_SONAR_PLUGIN, RANGE_PLUGIN, SONAR_ROBOT, SONAR_SENSOR
from sensor_fixtures import box, plugin_of, world_simulation

from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.sensors.range_sensor import INFRARED, ULTRASOUND, HectorSonar, RangeSensor
from mbot_sim_bridge.core.description.robot_model import parse_robot


def sonar_bot(tmp_path, wall_x=1.15, radiation="ultrasound", noise=0.0, yaw=0.0):
    sensors = (SONAR_SENSOR.format(name="front", plugin=RANGE_PLUGIN.format(radiation=radiation, noise=noise))
               + SONAR_SENSOR.format(name="rear", plugin=HECTOR_SONAR_PLUGIN.format(noise=noise)))
    sim = world_simulation(tmp_path, box("wall", (wall_x + 0.05, 0.0, 0.5), (0.1, 4.0, 1.0)))
    quaternion = (0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2))
    spawned = sim.spawn_robot(parse_robot(SONAR_ROBOT.format(sensors=sensors), "model 'sonar_bot'"), "sonar_bot",
                              Pose((0.0, 0.0, 0.0), quaternion))
    sim.step(100)
    return sim, plugin_of(spawned, RangeSensor), plugin_of(spawned, HectorSonar)


def test_both_read_the_wall_at_its_distance_within_1_cm(tmp_path):
    sim, gazebo_range, hector_sonar = sonar_bot(tmp_path)
    gazebo_range.update(sim.sim_time)
    hector_sonar.update(sim.sim_time)
    # The sonar sits 0.15 m ahead of the base centre, 0.3 m up (the ground is beyond 4 m for its lowest rays);
    # the wall's face is 1.15 m ahead: 1.0 m.
    print(f"figure: range to a wall 1.000 m away: gazebo_ros_range {gazebo_range.latest.range:.4f} m, "
          f"hector sonar {hector_sonar.latest.range:.4f} m")
    assert gazebo_range.latest.range == pytest.approx(1.0, abs=0.01)
    assert hector_sonar.latest.range == pytest.approx(1.0, abs=0.01)


def test_clear_reads_max_range_and_the_field_of_view_is_upstreams(tmp_path):
    sim, gazebo_range, hector_sonar = sonar_bot(tmp_path, yaw=np.pi)
    gazebo_range.update(sim.sim_time)
    hector_sonar.update(sim.sim_time)
    assert gazebo_range.latest.range == 4.0 and hector_sonar.latest.range == 4.0
    assert gazebo_range.field_of_view == 0.26  # the fov tag
    assert hector_sonar.field_of_view == pytest.approx(0.1)  # the smaller of the rays' spreads
    assert gazebo_range.radiation_type == ULTRASOUND == hector_sonar.radiation_type
    assert gazebo_range.timer.period == pytest.approx(1 / 20) and hector_sonar.timer.period == pytest.approx(0.1)


def test_radiation_other_than_ultrasound_is_infrared_and_noise_spreads_the_reading(tmp_path):
    sim, gazebo_range, hector_sonar = sonar_bot(tmp_path, radiation="infrared", noise=0.02)
    assert gazebo_range.radiation_type == INFRARED
    readings = []
    for _ in range(200):
        sim.step(1)
        gazebo_range.update(sim.sim_time)
        hector_sonar.update(sim.sim_time)
        readings.append((gazebo_range.latest.range, hector_sonar.latest.range))
    readings = np.array(readings)
    assert readings.mean(axis=0) == pytest.approx([1.0, 1.0], abs=0.01)
    assert readings.std(axis=0) == pytest.approx([0.02, 0.02], rel=0.25)
