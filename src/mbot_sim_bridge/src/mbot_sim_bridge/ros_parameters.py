"""The ROS parameter server as the simulation core's ``Parameters`` (``core/parameters.py``)."""
from typing import Any

import rospy

from .core.parameters import Parameters


class RosParameters(Parameters):
    def get(self, name: str, default: Any = None) -> Any:
        return rospy.get_param(name, default)

    def has(self, name: str) -> bool:
        return rospy.has_param(name)
