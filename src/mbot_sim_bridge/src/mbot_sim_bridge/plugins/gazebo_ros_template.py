"""``libgazebo_ros_template.so``: the ROS side of the template (gazebo_plugins' ``gazebo_ros_template.cpp``),
which publishes nothing.

A plugin's ROS side is ``RosPlugin`` mixed in before its core class, in the module named after the first file
name of the core class in the plugin table (the registry finds it there). ``__init__`` makes its topics through
``self.topics`` (``self.topics.publisher(resolve_in_namespace(namespace, topic), MessageType)``); ``update``
returns early when ``self.nobody_listens(now, publisher)``, otherwise calls the core's ``update`` and publishes
what it left, stamped ``ros_time(now)`` and filled by ``messages.py``. ``gazebo_ros_range.py`` is a short
example of a sensor that publishes.
"""
import rospy

from ..core.template import Template
from . import RosPlugin


class GazeboRosTemplate(RosPlugin, Template):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        rospy.loginfo(f"{self.label}: loaded; the template publishes nothing")
