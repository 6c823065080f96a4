"""``libgazebo_ros_force.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_force.cpp``).

Upstream keeps the last geometry_msgs/Wrench from ``topicName`` and, at every world update, adds its force to
``bodyName`` at the link's centre of mass and its torque, both in the world frame (Link::AddForce and AddTorque),
until another message replaces it; a reset does not clear it. Here the wrench is given to the engine before
every physics step in the same way. Upstream takes any value; here a wrench with a value that is not finite or
beyond MAX_WRENCH (apply_body_wrench's bound) is refused with one warning and the previous wrench stays.
"""
import math
from typing import Optional, Sequence

from .. import names
from ..body_wrenches import MAX_WRENCH, ZERO
from ..clock import UpdateTimer
from ..log import get_logger, warn_once
from ..params import Param
from ..plugin import Plugin
from . import body_link

_logger = get_logger(__name__)


class Force(Plugin):
    """Core of libgazebo_ros_force.so (GazeboRosForce)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosForce"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("bodyName", str, None, "the link pushed", required=True),
        Param("topicName", str, None, "geometry_msgs/Wrench subscribed: world-frame force at the link's centre "
                                      "of mass and torque", required=True),
    )
    needs_every_step = True

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        self.link = body_link(self)
        self.timer = UpdateTimer(1e-12, strict=True, start=context.simulation.sim_time)  # nothing to publish
        self.force, self.torque = ZERO, ZERO

    def set_wrench(self, force: Sequence[float], torque: Sequence[float]) -> Optional[str]:
        """A Wrench message: None when taken, else why it was refused (said once)."""
        values = [*force, *torque]
        if not all(math.isfinite(value) and abs(value) <= MAX_WRENCH for value in values):
            complaint = (f"{self.label}: a wrench must be finite and at most {MAX_WRENCH:g} in size; got {values}; "
                         "the previous wrench stays")
            warn_once(_logger, complaint)
            return complaint
        self.force, self.torque = tuple(map(float, force)), tuple(map(float, torque))
        return None

    def on_step(self, step_size: float):
        """For the next physics step: the engine forgets external forces after each step."""
        if self.force != ZERO or self.torque != ZERO:
            robot = self.context.robot
            self.context.engine.apply_link_wrench(robot.body, robot.link_index[self.link], self.force, self.torque)
