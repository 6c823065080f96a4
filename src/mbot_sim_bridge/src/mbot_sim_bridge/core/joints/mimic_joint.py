"""roboticsgroup's ``libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so`` without ROS
(roboticsgroup_upatras_gazebo_plugins ``mimic_joint_plugin.cpp``), and URDF ``<mimic>`` through it.

Before every physics step the follower (``mimicJoint``) is sent to leader·``multiplier`` + ``offset`` when it is
at least ``sensitiveness`` away: with ``hasPID`` by an effort from the PID gains under
``<robotNamespace>/<hasPID text, or gazebo_ros_control/pid_gains/<mimicJoint>>``, clamped to ``maxEffort``
(default: the follower's URDF effort limit); without, upstream sets the joint's position outright, and here a
position servo of unbounded force reaches it within the step (Bullet has no velocity-preserving teleport).

Gazebo classic ignores URDF ``<mimic>``; Gazebo users add this plugin for it. The bridge honours ``<mimic>``
itself by adding the plugin block a user would write for each mimicking joint no such plugin covers
(``Simulation``).
"""
import math

from .. import names
from ..clock import EveryStopTimer
from ..errors import ConfigError
from ..params import ERROR_MODEL_LIMIT, Param, non_negative
from ..plugin import Plugin
from ..ros_control.control_toolbox import Pid, clamp
from ..ros_control.hardware_interface import MAX_JOINT_SPEED, UNBOUNDED_EFFORT


class MimicJoint(Plugin):
    """Core of roboticsgroup's MimicJointPlugin."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "MimicJointPlugin"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the PID gains", warn_if_missing=False),
        Param("joint", str, None, "the leader joint", required=True),
        Param("mimicJoint", str, None, "the follower joint", required=True),
        Param("multiplier", float, 1.0, "follower = leader * multiplier + offset", warn_if_missing=False,
              minimum=-ERROR_MODEL_LIMIT, maximum=ERROR_MODEL_LIMIT),
        Param("offset", float, 0.0, "rad or m", warn_if_missing=False, minimum=-ERROR_MODEL_LIMIT,
              maximum=ERROR_MODEL_LIMIT),
        non_negative("sensitiveness", float, 0.0, "smallest difference acted on", warn_if_missing=False),
        non_negative("maxEffort", float, None, "N·m or N with hasPID; absent: the follower's effort limit",
                     warn_if_missing=False),
        Param("hasPID", str, None, "present: PID effort control, gains under this namespace (empty: "
              "gazebo_ros_control/pid_gains/<mimicJoint>)", warn_if_missing=False),
    )
    needs_every_step = True

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        self.leader, self.follower = self.named_joints(params, ("joint", "mimicJoint"))
        joint = context.robot.model.joints[self.follower]
        self.lower, self.upper = joint.lower, joint.upper  # -inf and inf for a joint without limits
        self.max_effort = params["maxEffort"] if params["maxEffort"] is not None else (
            joint.effort if joint.effort > 0 else math.inf)
        self.pid = None
        if element.find("hasPID") is not None:
            name = params["hasPID"] or f"gazebo_ros_control/pid_gains/{self.follower}"
            namespace = f"{self.robot_namespace().rstrip('/')}/{name}"
            self.pid = Pid.from_params(context.simulation.parameters.get(namespace), namespace)
            if self.pid is None:
                raise ConfigError(f"{context.where(element)}: {self.label}: hasPID: no usable gains under "
                                  f"{namespace} (p, i, d)")
        self.driven_joints = (self.follower,)
        self.timer = EveryStopTimer()  # all its work is in on_step: nothing of its own stops the loop
        self.drive(context.simulation.step_size)

    def drive(self, step_size: float):
        robot, params = self.context.robot, self.params
        (leader, leader_speed, _), (follower, _, _) = robot.joint_state([self.leader, self.follower])
        # Held to the follower's travel: a target far past it (a multiplier of 1e6) flung the whole robot away.
        target = clamp(leader * params["multiplier"] + params["offset"], self.lower, self.upper)
        if abs(target - follower) < params["sensitiveness"]:
            return
        if self.pid is None:
            speed = 0.0 if target in (self.lower, self.upper) else clamp(leader_speed * params["multiplier"],
                                                                         -MAX_JOINT_SPEED, MAX_JOINT_SPEED)
            robot.set_joint_position(self.follower, target, UNBOUNDED_EFFORT, speed)
        else:
            limit = min(self.max_effort, UNBOUNDED_EFFORT)
            robot.set_joint_effort(self.follower, clamp(self.pid.compute(target - follower, step_size), -limit, limit))

    def on_step(self, step_size: float):
        self.drive(step_size)

    def joints_set(self, positions):
        """Aim at the leader's new position before the next step, not at the old one."""
        self.drive(self.context.simulation.step_size)

    def reset(self, now: float):
        super().reset(now)
        if self.pid is not None:
            self.pid.reset()
