"""The ROS side of the emulated gazebo_ros plugins: one module and class per Gazebo ``.so``.

Each class extends the plugin's core class (``core/``) with its publishers and subscribers and nothing else;
``registry.REGISTRY`` maps the Gazebo file name to it. Updates run in the loop thread that owns the engine;
subscriber callbacks only store values under the core's lock.
"""
import warnings
from typing import Optional

import rospy


def loop_publisher(name: str, message_type) -> rospy.Publisher:
    """A publisher written to synchronously by the loop thread.

    rospy's queued publishers hand each message to a writer thread and then call time.sleep(0) to yield the
    GIL, a hand-off that costs more than a physics step. The loop is the only thread publishing these topics,
    so it writes them itself (queue_size=None); rospy warns about that choice, which here is deliberate.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)
        return rospy.Publisher(name, message_type, queue_size=None)


def ros_time(sim_seconds: float) -> rospy.Time:
    """A stamp for sim time: plugins stamp with the simulation's time, never rospy.Time.now()."""
    return rospy.Time(*divmod(int(round(sim_seconds * 1e9)), 1000000000))


def resolve_in_namespace(namespace: Optional[str], name: str) -> str:
    """A plugin topic: absolute names stand, relative ones go under the plugin namespace."""
    if name.startswith("/"):
        return name
    return rospy.names.ns_join(namespace or "/", name)
