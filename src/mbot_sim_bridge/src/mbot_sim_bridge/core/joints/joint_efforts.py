"""Efforts applied to joints from outside, as gazebo_ros's ``/gazebo/apply_joint_effort`` and
``/gazebo/clear_joint_forces`` schedule them (gazebo_ros_pkgs noetic-devel ``gazebo_ros_api_plugin.cpp``).

A job holds a joint, an effort (N·m or N) and a sim-time window (timed_jobs). Before every physics step of its
window the job's effort is added to the joint, as upstream's Joint::SetForce adds to what controllers and
plugins set in the same step; each job's effort is first cut to the joint's URDF effort limit, as Gazebo's
Joint::CheckAndTruncateForce cuts each SetForce. A joint is named as Gazebo's Model::GetJoint finds it: "joint"
(the first model, in the world's order, with such a movable joint) or "model::joint".
"""
import math
from typing import Dict, Iterable, NamedTuple, Optional, Tuple

from ..errors import ModelError
from ..timed_jobs import TimedJobs, check_window

# apply_joint_effort's largest effort (N·m or N), as apply_body_wrench's largest force: beyond it the physics
# would turn the model's state NaN.
MAX_EFFORT = 1e6
JOINT_NOT_FOUND = "ApplyJointEffort: joint not found"


class EffortJob(NamedTuple):
    model: str
    joint: str
    effort: float
    start: float
    duration: float


def find_joint(name: str, movable_joints: Iterable[Tuple[str, Iterable[str]]]) -> Optional[Tuple[str, str]]:
    """(model, joint) of a joint named "joint" or "model::joint" among the models' movable joints, given in the
    world's order as (model, joint names); None when none has it."""
    scope, _, joint = name.rpartition("::")
    for model, joints in movable_joints:
        if scope in ("", model) and joint in joints:
            return model, joint
    return None


def requested_job(joint_name: str, effort: float, start: float, duration: float, now: float,
                  movable_joints: Iterable[Tuple[str, Iterable[str]]], effort_limit) -> EffortJob:
    """An apply_joint_effort request as a job, checked: an unknown joint raises ModelError with upstream's
    message; an effort that is not finite or beyond MAX_EFFORT, or a start or duration beyond what a ROS time
    holds, raises one naming the value (upstream would take them, and NaN the model). A start before ``now``
    is now, as upstream's. ``effort_limit(model, joint)``: the URDF effort limit, None without one."""
    found = find_joint(joint_name, movable_joints)
    if found is None:
        raise ModelError(JOINT_NOT_FOUND)
    if not (math.isfinite(effort) and abs(effort) <= MAX_EFFORT):
        raise ModelError(f"ApplyJointEffort: joint '{joint_name}': effort must be finite and at most "
                         f"{MAX_EFFORT:g} in size; got {effort}")
    check_window(f"ApplyJointEffort: joint '{joint_name}'", start, duration)
    limit = effort_limit(*found)
    if limit is not None:
        effort = min(max(effort, -limit), limit)
    return EffortJob(*found, float(effort), max(start, now), duration)


class JointEfforts(TimedJobs[EffortJob]):
    """apply_joint_effort's jobs."""

    def clear(self, model: str, joint: Optional[str] = None):
        """Drop the jobs of one joint of ``model``, or of all its joints (its deletion)."""
        self.remove(lambda job: job.model == model and joint in (None, job.joint))

    def clear_named(self, name: str):
        """clear_joint_forces: upstream drops the jobs of every joint of that name, whatever its model; a
        "model::joint" drops that joint's."""
        scope, _, joint = name.rpartition("::")
        self.remove(lambda job: job.joint == joint and scope in ("", job.model))

    def due(self, now: float) -> Dict[Tuple[str, str], float]:
        """(model, joint) -> the sum of the efforts acting in the step starting at ``now``."""
        total: Dict[Tuple[str, str], float] = {}
        for job in self.acting(now):
            total[(job.model, job.joint)] = total.get((job.model, job.joint), 0.0) + job.effort
        return total
