"""gazebo_ros_link_attacher's ``libgazebo_ros_link_attacher.so`` without ROS (pal-robotics, melodic-devel
``gazebo_ros_link_attacher.cpp``), a world plugin.

``attach`` joins two links where they are now: upstream creates a revolute joint with both stops at 0 between
them; here a PyBullet fixed constraint does it (``fixed_joints.FixedJoints``). Asked again for the same four
names it re-attaches, as upstream reuses its joint; ``detach`` of a pair never attached answers false. Upstream
reads no tags. Unlike upstream, whose joints survive a world reset and a deleted model, here a reset of either
kind releases every attachment and deleting a model releases those that hold it: the models come back where they
were spawned, and a joint pulling them together there would throw them.
"""
from typing import Tuple

from ..clock import EveryStopTimer
from ..log import get_logger
from ..plugin import WorldPlugin
from .fixed_joints import FixedJoints

_logger = get_logger(__name__)

Names = Tuple[str, str, str, str]  # model_name_1, link_name_1, model_name_2, link_name_2


class LinkAttacher(WorldPlugin):
    """Core of GazeboRosLinkAttacher: the attach and detach services' work, in the loop's thread."""
    GAZEBO_CLASS = "GazeboRosLinkAttacher"

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.read_params()  # none: says once that any tag given has no effect
        self.timer = EveryStopTimer()
        self.joints = FixedJoints(context.simulation)

    def attach(self, names: Names) -> Tuple[bool, str]:
        """(ok, what upstream logs) for the attach service."""
        if self.joints.holds(names):
            return True, "Joint already existed, reusing it."
        error = self.joints.attach(names, names)
        return (False, error) if error else (True, "Attach finished.")

    def detach(self, names: Names) -> Tuple[bool, str]:
        if not self.joints.detach(names):
            return False, (f"no joint attaches link '{names[1]}' of model '{names[0]}' to link '{names[3]}' of "
                           f"model '{names[2]}'")
        return True, ""

    def model_deleted(self, name: str):
        self.joints.release_model(name)

    def reset(self, now: float):
        self.joints.release_all()

    def close(self):
        self.joints.release_all()
