"""``libgazebo_grasp_fix.so``: no ROS side (upstream publishes its grasp events on Gazebo's own transport, which
the bridge does not have); its attachments and releases are logged."""
from ..core.manipulation.grasp_fix import GraspFix
from . import RosPlugin


class GazeboGraspFix(RosPlugin, GraspFix):
    pass
