"""Wrenches applied to links from outside, as gazebo_ros's ``/gazebo/apply_body_wrench`` and
``/gazebo/clear_body_wrenches`` schedule them (gazebo_ros_pkgs noetic-devel ``gazebo_ros_api_plugin.cpp``).

A job holds a link, a force and a torque (world frame) and a sim-time window. Before every physics step each job
whose window holds the time sets its link's force (at the centre of mass) and torque, as Gazebo's SetForce and
SetTorque: of several jobs on one link the last one wins. A job ends once the time passes start + duration; a
negative duration never ends, one of 0 acts for the step at its start. What was applied in the last step is
what ``libgazebo_ros_f3d.so`` reports (Gazebo's Link::WorldForce at the start of the next update).

The request's wrench becomes the job's as upstream transforms it: the torque gains reference_point × force;
with an empty, "world" or "map" reference_frame both stay as given; with an entity's frame both are rotated by
that frame's orientation relative to the link, and the torque gains (frame position relative to the link) ×
force. The result is applied in the world frame, so a wrench given in the link's own frame acts along the world
axes (upstream's "FIXME map is really wrong").
"""
import math
from typing import Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from .errors import ModelError
from .geometry import Pose, Vector, inverse, compose, rotate
from .timed_jobs import TimedJobs, check_window

ZERO = (0.0, 0.0, 0.0)
WORLD_FRAMES = ("", "world", "map", "/map")
# apply_body_wrench's largest force (N), torque (N·m) and reference point coordinate (m).
MAX_WRENCH = 1e6


class WrenchJob(NamedTuple):
    model: str
    link: str
    force: Vector
    torque: Vector
    start: float
    duration: float


def target_wrench(force: Sequence[float], torque: Sequence[float], reference_point: Sequence[float],
                  body_pose: Pose, frame_pose: Optional[Pose]) -> Tuple[Vector, Vector]:
    """The force and torque a request makes (see the module docstring); ``frame_pose`` None: a world frame."""
    force = np.asarray(force, dtype=float)
    torque = np.asarray(torque, dtype=float) + np.cross(reference_point, force)
    if frame_pose is None:
        return tuple(force.tolist()), tuple(torque.tolist())
    relative = compose(inverse(body_pose), frame_pose)  # the frame in the link's frame
    force = np.asarray(rotate(relative.orientation, force))
    torque = np.asarray(rotate(relative.orientation, torque)) + np.cross(relative.position, force)
    return tuple(force.tolist()), tuple(torque.tolist())


def requested_job(body: str, reference_frame: str, reference_point: Sequence[float], force: Sequence[float],
                  torque: Sequence[float], start: float, duration: float, now: float,
                  link_names: Callable[[str], List[str]], link_pose: Callable[[str, str], Pose],
                  entity_pose: Callable[[str], Optional[Pose]]) -> WrenchJob:
    """An apply_body_wrench request as a job on link ``body`` ("model::link"), checked as gazebo_ros checks it: an
    unknown body or frame raises ModelError with upstream's message, and so does a value that is not finite or
    beyond MAX_WRENCH (the physics would turn the model's state NaN), or a start time or duration that is not
    finite or beyond timed_jobs.MAX_JOB_TIME. A start before ``now`` (the sim time) is now, as upstream's. The
    simulation's ``link_names(model)``, ``link_pose(model, link)`` and ``entity_pose(name)`` (None: no such
    entity) say what exists where."""
    model, _, link = body.partition("::")
    if link not in link_names(model):
        known = ", ".join(f"{model}::{name}" for name in link_names(model)) or "no such model"
        raise ModelError(f"ApplyBodyWrench: body does not exist: '{body}' ({known})")
    values = [*reference_point, *force, *torque]
    if not all(math.isfinite(value) and abs(value) <= MAX_WRENCH for value in values):
        raise ModelError(f"ApplyBodyWrench: body '{body}': reference point, force and torque must be finite and "
                         f"at most {MAX_WRENCH:g} in size; got {values}")
    check_window(f"ApplyBodyWrench: body '{body}'", start, duration)
    frame_pose = None
    if reference_frame not in WORLD_FRAMES:
        frame_pose = entity_pose(reference_frame)
        if frame_pose is None:
            raise ModelError(f"ApplyBodyWrench: reference_frame '{reference_frame}' is not a valid entity name")
    force, torque = target_wrench(force, torque, reference_point, link_pose(model, link), frame_pose)
    return WrenchJob(model, link, force, torque, max(start, now), duration)


class BodyWrenches(TimedJobs[WrenchJob]):
    """apply_body_wrench's jobs, and what they applied in the last step."""

    def __init__(self):
        super().__init__()
        self.applied: Dict[Tuple[str, str], Tuple[Vector, Vector]] = {}

    def clear(self, model: str, link: Optional[str] = None):
        """Drop the jobs of one link, or of every link of ``model`` (its deletion)."""
        self.remove(lambda job: job.model == model and link in (None, job.link))

    def due(self, now: float) -> Dict[Tuple[str, str], Tuple[Vector, Vector]]:
        """(model, link) -> (force, torque) to apply in the step starting at ``now``: of several jobs on one link
        the last one wins (Gazebo's SetForce and SetTorque)."""
        self.applied = {(job.model, job.link): (job.force, job.torque) for job in self.acting(now)}
        return self.applied

    def applied_to(self, model: str, link: str) -> Tuple[Vector, Vector]:
        return self.applied.get((model, link), (ZERO, ZERO))
