"""~performance_metrics (gazebo_msgs/PerformanceMetrics), as Gazebo 11 publishes it while subscribed, once per
wall second: the real-time factor over that second, and per sensor (Gazebo's scoped name world::model::link::sensor)
its updates per sim second and per wall second; fps is the camera's frames per wall second, -1 for other sensors.
A sensor counts the updates of its ROS plugin (a sensor without one is not simulated here)."""
import time
from typing import Dict

from gazebo_msgs.msg import PerformanceMetrics, SensorPerformanceMetric

from .plugins import loop_publisher, ros_time

CAMERA_TYPES = ("camera", "depth", "multicamera", "wideanglecamera")
PERIOD_SECONDS = 1.0  # of wall time


class PerformanceMetricsPublisher:
    def __init__(self, sim):
        self.sim = sim
        self.publisher = loop_publisher("~performance_metrics", PerformanceMetrics)
        self._since = None  # (wall time, sim time, update counts) at the start of the period

    def publish(self):
        if self.publisher.get_num_connections() == 0:
            self._since = None
            return
        now = (time.monotonic(), self.sim.sim_time, dict(self.sim.sensor_updates))
        if self._since is None:
            self._since = now
            return
        wall = now[0] - self._since[0]
        if wall < PERIOD_SECONDS:
            return
        sim_seconds = now[1] - self._since[1]
        message = PerformanceMetrics(real_time_factor=sim_seconds / wall)
        message.header.stamp = ros_time(now[1])
        for name, (plugin, updates) in self._sensor_updates(now[2], self._since[2]).items():
            real_rate = updates / wall
            message.sensors.append(SensorPerformanceMetric(
                name=name, sim_update_rate=updates / sim_seconds if sim_seconds > 0 else 0.0,
                real_update_rate=real_rate, fps=real_rate if plugin.sensor.get("type") in CAMERA_TYPES else -1.0))
        self.publisher.publish(message)
        self._since = now

    def _sensor_updates(self, counts: Dict, before: Dict) -> Dict:
        """Scoped sensor name -> (its plugin, updates in the period), for every sensor plugin running now."""
        world = self.sim.world.name
        updates = {}
        for spawned in self.sim.models.values():
            for plugin in spawned.plugins:
                if plugin.sensor is not None:  # on the link its <gazebo reference> is lumped into, as Gazebo's
                    link = spawned.robot.model.lumped_into[plugin.context.link][0]
                    name = f"{world}::{spawned.name}::{link}::{plugin.sensor.get('name')}"
                    updates.setdefault(name, (plugin, counts.get(plugin, 0) - before.get(plugin, 0)))
        return updates
