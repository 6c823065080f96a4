"""The ROS side of the emulated gazebo_ros plugins: one module and class per Gazebo ``.so``.

A plugin reads its tags through the core's Param tables, takes core objects (engine, robot, timers) and
only publishes and subscribes. The node calls ``update`` when the plugin's timer is due, in the thread
that owns the engine.
"""
import warnings
from dataclasses import dataclass
from typing import Callable, Optional

import rospy
from tf2_msgs.msg import TFMessage

from ..core.clock import UpdateTimer
from ..core.engine import Engine, SpawnedRobot


def loop_publisher(name: str, message_type) -> rospy.Publisher:
    """A publisher written to synchronously by the loop thread.

    rospy's queued publishers hand each message to a writer thread and then call time.sleep(0) to yield the
    GIL, a hand-off that costs more than a physics step. The loop is the only thread publishing these topics,
    so it writes them itself (queue_size=None); rospy warns about that choice, which here is deliberate.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)
        return rospy.Publisher(name, message_type, queue_size=None)


class TransformBroadcaster:
    """tf2_ros.TransformBroadcaster's job (a TFMessage on /tf) through a loop publisher."""

    def __init__(self):
        self.publisher = loop_publisher("/tf", TFMessage)

    def send_transform(self, transform):
        self.publisher.publish(TFMessage([transform]))


@dataclass
class PluginContext:
    engine: Engine
    robot: SpawnedRobot
    tf_broadcaster: TransformBroadcaster  # shared by all plugins
    stamp: Callable[[], rospy.Time]  # the current sim time as a ROS stamp


class BridgePlugin:
    """Base of every emulated plugin."""

    timer: UpdateTimer
    # True when the plugin must see every physics step (the diff drive's encoder odometry).
    needs_every_step = False
    # Joints whose states the plugin publishes; the bridge publishes the other movable joints itself.
    joint_states_published = ()

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
