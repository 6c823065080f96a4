"""roboticsgroup's mimic joint plugin: nothing on ROS but its line in the log (its PID gains come from the
parameter server, read by the core)."""
import rospy

from ..core.joints.mimic_joint import MimicJoint
from . import RosPlugin


class RosMimicJoint(RosPlugin, MimicJoint):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.params
        drive = "PID effort" if self.pid is not None else "position servo"
        rospy.loginfo(f"{self.label}: joint '{self.follower}' = '{self.leader}' x {params['multiplier']:g} + "
                      f"{params['offset']:g} ({drive})")
