"""performance_metrics.py: once per wall second while subscribed, the real-time factor over it and each sensor's
updates per sim and per wall second under Gazebo's scoped name; nothing without a subscriber."""
import pytest
from sensor_fixtures import with_imu, world_simulation

from mbot_sim_bridge import performance_metrics
from mbot_sim_bridge.core.description.robot_model import parse_robot
from test_model_states import CountedConnections


def test_rates_over_each_wall_second_and_only_while_subscribed(monkeypatch, tmp_path, mbot_urdf):
    monkeypatch.setattr(performance_metrics, "loop_publisher", CountedConnections)
    wall = [100.0]
    monkeypatch.setattr(performance_metrics.time, "monotonic", lambda: wall[0])
    sim = world_simulation(tmp_path)
    sim.spawn_robot(parse_robot(with_imu(mbot_urdf), "model 'mbot'"), "mbot")
    metrics = performance_metrics.PerformanceMetricsPublisher(sim)
    sim.step(100)
    metrics.publish()
    assert metrics.publisher.sent == []  # nobody subscribes
    metrics.publisher.connections = 1
    metrics.publish()  # the period starts
    sim.step(1000)
    wall[0] += 0.5
    metrics.publish()
    assert metrics.publisher.sent == []  # half a wall second
    wall[0] += 1.5
    metrics.publish()
    (message,) = metrics.publisher.sent
    assert message.real_time_factor == pytest.approx(0.5)  # 1 s of sim time in 2 s of wall time
    assert message.header.stamp.to_sec() == pytest.approx(1.1)
    (imu,) = message.sensors
    print(f"figure: performance_metrics: imu {imu.sim_update_rate:g} updates per sim second (updateRateHZ 100)")
    assert imu.name == "default::mbot::base_footprint::imu"  # imu_link is lumped into the root
    assert (imu.sim_update_rate, imu.real_update_rate, imu.fps) == (pytest.approx(100.0, abs=1.0),
                                                                    pytest.approx(50.0, abs=0.5), -1.0)
