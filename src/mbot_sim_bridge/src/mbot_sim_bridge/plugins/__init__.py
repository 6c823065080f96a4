"""The ROS side of the emulated gazebo_ros plugins: one module and class per Gazebo ``.so``.

A plugin reads its tags through the core's Param tables, takes core objects (engine, robot, timers) and
only publishes and subscribes. The node calls ``update`` when the plugin's timer is due, in the thread
that owns the engine.
"""
from dataclasses import dataclass
from typing import Callable, Optional

import rospy

from ..core.clock import UpdateTimer
from ..core.engine import Engine, SpawnedRobot


@dataclass
class PluginContext:
    engine: Engine
    robot: SpawnedRobot
    tf_broadcaster: object  # tf2_ros.TransformBroadcaster shared by all plugins
    stamp: Callable[[], rospy.Time]  # the current sim time as a ROS stamp


class BridgePlugin:
    """Base of every emulated plugin."""

    timer: UpdateTimer
    # True when the plugin must see every physics step (the diff drive's encoder odometry).
    needs_every_step = False

    def on_step(self, step_size: float):
        """Called after every physics step when ``needs_every_step``."""

    def update(self, now: float):
        """Called when ``timer`` is due, with the sim time in seconds."""

    def reset(self, now: float):
        """World or simulation reset (Gazebo calls the plugin's Reset())."""
        self.timer.reset(now)

    def close(self):
        """The model is deleted or the node stops: drop publishers and subscribers."""


def resolve_in_namespace(namespace: Optional[str], name: str) -> str:
    """A plugin topic: absolute names stand, relative ones go under the plugin namespace."""
    if name.startswith("/"):
        return name
    return rospy.names.ns_join(namespace or "/", name)


def resolve_frame(frame: str) -> str:
    """tf::resolve with an empty tf_prefix: a leading '/' is stripped."""
    return frame.lstrip("/")
