"""Ground truth: ``libgazebo_ros_p3d.so`` (gazebo_plugins noetic-devel ``gazebo_ros_p3d.cpp``).

What Gazebo publishes, copied here:
- nav_msgs/Odometry of ``bodyName`` (required; a link lumped by a fixed joint is measured where it really is,
  and named after the link sdformat keeps, as Gazebo renames it), child_frame_id = that name,
  header.frame_id = ``frameName`` (default "world", a leading "/" dropped).
- ``frameName`` "world" or "map": the world pose and world-frame velocities. Any other name must be a link of
  the same model: the pose becomes relative to it, and the velocities are the differences rotated *by* that
  link's world rotation (Gazebo's RotateVector, not its inverse).
- pose.position += ``xyzOffset`` (added in the output frame), orientation = rpyOffset ∘ orientation.
- ``gaussianNoise`` goes on the six twist values only (the pose is exact); both covariance diagonals are
  gaussianNoise².
- ``updateRate`` 0 = every physics step; nothing is computed while nobody subscribes.
- topicName is required (Gazebo stops with a FATAL without it; the bridge refuses the spawn).
"""
from typing import NamedTuple, Optional, Tuple

import numpy as np

from .. import names
from ..clock import UpdateTimer
from ..errors import ConfigError
from ..geometry import Pose, compose, inverse, pose_from_xyz_rpy, rotation_matrix
from .body_sensors import IDLE_PERIOD, read_vector_param
from ..params import ERROR_MODEL_LIMIT, Param, non_negative, rate
from ..plugin import Plugin

WORLD_FRAMES = ("world", "/world", "map", "/map")


class GroundTruth(NamedTuple):
    stamp: float
    pose: Pose
    linear: Tuple[float, float, float]
    angular: Tuple[float, float, float]
    covariance: float  # on both 6x6 diagonals


class P3D(Plugin):
    """Core of libgazebo_ros_p3d.so (GazeboRosP3D)."""
    NAMESPACE_RULE = names.ROOT

    GAZEBO_CLASS = "GazeboRosP3D"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("bodyName", str, None, "the link measured", required=True),
        Param("topicName", str, None, "nav_msgs/Odometry topic", required=True),
        Param("frameName", str, "world", "world, map, or a link of this model", warn_if_missing=False),
        Param("xyzOffset", str, "0 0 0", "m, added to the position", warn_if_missing=False),
        Param("rpyOffset", str, "0 0 0", "rad, pre-multiplies the orientation", warn_if_missing=False),
        non_negative("gaussianNoise", float, 0.0, "stddev on the twist", warn_if_missing=False,
                     maximum=ERROR_MODEL_LIMIT),
        rate("updateRate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
    )
    IGNORED_TAGS = ("alwaysOn",)

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        robot = context.robot
        where = context.where(element)
        links = robot.model.lumped_into
        self.body = self.params["bodyName"]
        if self.body not in links:
            raise ConfigError(f"{where}: {self.label}: bodyName: {self.body} does not exist (links: "
                              f"{', '.join(sorted(links))})")
        self.child_frame = links[self.body][0]
        frame = self.params["frameName"]
        self.reference: Optional[str] = None
        if frame not in WORLD_FRAMES:
            if frame not in links:
                raise ConfigError(f"{where}: {self.label}: frameName: {frame} does not exist in model "
                                  f"'{context.model.name}' (use world, map or one of {', '.join(sorted(links))})")
            self.reference = frame
        self.frame_name = links[frame][0] if frame in links else frame.lstrip("/")
        self.xyz_offset = np.asarray(read_vector_param(element, "xyzOffset", self.label, where) or (0.0, 0.0, 0.0))
        rpy = read_vector_param(element, "rpyOffset", self.label, where) or (0.0, 0.0, 0.0)
        self.rotation_offset = pose_from_xyz_rpy((0.0, 0.0, 0.0), rpy)
        self.noise = self.params["gaussianNoise"]
        self.rng = context.random_stream(element.get("name") or "p3d")
        self.timer = UpdateTimer(self.params["updateRate"], start=context.simulation.sim_time)
        self.period = self.timer.period
        self.latest: Optional[GroundTruth] = None

    def idle(self, now: float):
        """While nothing reads the ground truth, look again only every IDLE_PERIOD instead of every step."""
        self.timer.period = max(self.period, IDLE_PERIOD)

    def read(self, now: float) -> GroundTruth:
        robot = self.context.robot
        pose = robot.link_world_pose(self.body)
        linear, angular = (np.asarray(v) for v in robot.link_world_velocity(self.body))
        if self.reference is not None:
            frame = robot.link_world_pose(self.reference)
            frame_linear, frame_angular = (np.asarray(v) for v in robot.link_world_velocity(self.reference))
            pose = compose(inverse(frame), pose)
            rotation = np.asarray(rotation_matrix(frame.orientation))
            linear, angular = rotation @ (linear - frame_linear), rotation @ (angular - frame_angular)
        orientation = compose(self.rotation_offset, Pose((0.0, 0.0, 0.0), pose.orientation)).orientation
        position = tuple(np.asarray(pose.position) + self.xyz_offset)
        if self.noise > 0:
            noise = self.rng.normal(0.0, self.noise, 6)
            linear, angular = linear + noise[:3], angular + noise[3:]
        return GroundTruth(now, Pose(position, tuple(orientation)), tuple(linear), tuple(angular), self.noise ** 2)

    def update(self, now: float):
        self.timer.period = self.period
        self.latest = self.read(now)
