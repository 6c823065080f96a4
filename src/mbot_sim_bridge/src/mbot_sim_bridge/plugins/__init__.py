"""The ROS side of the emulated gazebo_ros plugins: one module and class per Gazebo ``.so``.

Each class is ``RosPlugin`` mixed into the plugin's core class (``core/``): it adds the publishers and
subscribers (owned by ``self.topics``) and nothing else, and calls only the core's hooks (``update``, ``idle``
and the values they leave). ``registry.REGISTRY`` maps the Gazebo file name to it. Updates run in the loop
thread that owns the engine; subscriber callbacks only store values under the core's lock. Messages are
built in ``messages.py``.
"""
from typing import Optional

import rospy

from ..loop_publishing import LoopPublisher


def loop_publisher(name: str, message_type) -> LoopPublisher:
    """A publisher written to synchronously by the loop thread (loop_publishing.py)."""
    return LoopPublisher(name, message_type)


def ros_time(sim_seconds: float) -> rospy.Time:
    """A stamp for sim time: plugins stamp with the simulation's time, never rospy.Time.now()."""
    return rospy.Time(*divmod(int(round(sim_seconds * 1e9)), 1000000000))


def resolve_in_namespace(namespace: Optional[str], name: str) -> str:
    """A plugin topic: absolute names stand, relative ones go under the plugin namespace."""
    if name.startswith("/"):
        return name
    return rospy.names.ns_join(namespace or "/", name)


class PluginTopics:
    """The publishers, services and subscribers one plugin owns: made the loop's way, asked whether anyone
    listens (the loop publishes synchronously, so a topic nobody takes is work skipped), and closed together."""

    def __init__(self):
        self._owned = []

    def publisher(self, name: str, message_type) -> LoopPublisher:
        return self.own(loop_publisher(name, message_type))

    def own(self, handle):
        """Close ``handle`` (a rospy Service, Subscriber or TrackedSubscriber) with the others; returns it."""
        self._owned.append(handle)
        return handle

    @staticmethod
    def listened(*publishers: Optional[LoopPublisher]) -> bool:
        return any(publisher is not None and publisher.get_num_connections() > 0 for publisher in publishers)

    def close(self):
        for handle in self._owned:
            handle.shutdown() if isinstance(handle, rospy.Service) else handle.unregister()
        self._owned.clear()


class RosPlugin:
    """Mixed in before a core plugin class: ``self.topics``, closed with the plugin."""

    def __init__(self, *args, **kwargs):
        self.topics = PluginTopics()
        super().__init__(*args, **kwargs)

    def nobody_listens(self, now: float, *publishers: Optional[LoopPublisher]) -> bool:
        """Whether none of ``publishers`` has a subscriber; the core then idles (``idle(now)``) and the update
        stops there, as gazebo_ros's sensors work only while someone listens."""
        if self.topics.listened(*publishers):
            return False
        self.idle(now)
        return True

    def close(self):
        self.topics.close()
        super().close()
