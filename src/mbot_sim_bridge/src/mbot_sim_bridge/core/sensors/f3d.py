"""``libgazebo_ros_f3d.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_f3d.cpp``).

Upstream publishes the body's Link::WorldForce and WorldTorque at every world update: the force and torque
applied to the link from outside in that step (ODE's accumulators, which gravity, joints and contacts do not
enter), world frame, torque as given. Here that is what ``/gazebo/apply_body_wrench`` applied to the link in
the last physics step (``body_wrenches.py``), zero otherwise. ``frameName`` only labels the header (upstream
says it is "not used, default to world" and still puts it there, with the tf prefix). ``bodyName`` must be a
link Gazebo keeps (one lumped by a fixed joint is not found, as in Gazebo).
"""
from typing import NamedTuple, Optional

from .. import names
from ..clock import UpdateTimer
from ..errors import ConfigError
from ..geometry import Vector
from .body_sensors import IDLE_PERIOD
from ..params import Param
from ..plugin import Plugin



class AppliedWrench(NamedTuple):
    stamp: float
    force: Vector
    torque: Vector


class F3D(Plugin):
    """Core of libgazebo_ros_f3d.so (GazeboRosF3D)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosF3D"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("bodyName", str, None, "the link whose applied wrench is reported", required=True),
        Param("topicName", str, None, "geometry_msgs/WrenchStamped", required=True),
        Param("frameName", str, "world", "frame_id of the header (the values stay in the world frame)"),
    )
    IGNORED_TAGS = ("alwaysOn", "updateRate")

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        self.link = self.params["bodyName"]
        links = context.robot.link_index
        if self.link not in links:
            raise ConfigError(f"{context.where(element)}: {self.label}: bodyName: {self.link} does not exist in "
                              f"model '{context.model.name}' (links after lumping fixed joints: "
                              f"{', '.join(sorted(links))})")
        self.timer = UpdateTimer(0.0, start=context.simulation.sim_time)
        self.latest: Optional[AppliedWrench] = None

    def idle(self, now: float):
        """While nobody subscribes, look only every IDLE_PERIOD rather than every step (upstream returns early)."""
        self.timer.period = IDLE_PERIOD

    def update(self, now: float):
        self.timer.period = 0.0
        force, torque = self.context.simulation.wrenches.applied_to(self.context.model.name, self.link)
        self.latest = AppliedWrench(now, force, torque)
