"""gazebo-pkgs' ``libgazebo_grasp_fix.so`` (gazebo_grasp_plugin ``GazeboGraspFix.cpp``, ``GazeboGraspGripper.cpp``),
a model plugin without a ROS side (upstream publishes its grasp events on Gazebo's own transport only).

At ``update_rate``, for every object touching the ``<gripper_link>``s of an ``<arm>``: the force each finger puts
on it (the mean of its contact points' normal forces); when two of them point more than
``forces_angle_tolerance`` apart and the smaller is at least 0.3 of the larger (upstream's CheckGrip), the object
is gripped and its count rises (up to ``max_grip_count``); past ``grip_count_threshold`` it is attached to the
arm's ``palm_link`` where it is, by a fixed joint (``fixed_joints.FixedJoints``), optionally colliding with
nothing meanwhile (``disable_collisions_on_attach``), and where each finger touched it is remembered. An object
not gripped loses a count per update; once at or below the threshold, it is released when a remembered contact
point on a finger has moved more than ``release_tolerance`` toward or away from the object's centre (the fingers
opened). Objects are other models' links; static ones are left alone, as upstream.

Here, unlike upstream: updates go by sim time (upstream's by wall time, so its grasps depend on the machine's
load); the contacts are those of the update's step (upstream averages those of the period since the last); a
palm or finger link the robot lacks (or has lumped into another by a fixed joint, as Gazebo does) refuses the
spawn naming the links there are, where upstream leaves the arm out with an error; a reset releases everything.
"""
import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple
from xml.etree import ElementTree

import numpy as np

from ..clock import UpdateTimer
from ..errors import ConfigError
from ..geometry import IDENTITY, Pose, compose, inverse
from ..log import get_logger
from ..params import Param, non_negative
from ..plugin import Plugin
from .fixed_joints import FixedJoints

_logger = get_logger(__name__)

# CheckGrip's length ratio: the weaker of two opposing forces is at least this fraction of the stronger.
FORCE_RATIO = 0.3
# CheckGrip ignores forces below this (N), as upstream's 1e-4.
NEGLIGIBLE_FORCE = 1.0e-4
MAX_COUNT = 1_000_000

ObjectLink = Tuple[str, str]  # (model, link)


@dataclass(frozen=True)
class Arm:
    name: str
    palm: str
    fingers: Tuple[str, ...]


@dataclass
class _Touch:
    """What one finger does to one object at an update, the points in the finger's frame."""
    arm: str
    finger: str
    force: np.ndarray  # on the object, world frame (N)
    contact: np.ndarray  # the contact points' mean
    object_position: np.ndarray


def grips(forces: Sequence[np.ndarray], min_angle: float) -> bool:
    """Upstream's CheckGrip: two forces more than ``min_angle`` (rad) apart, the weaker at least FORCE_RATIO of
    the stronger."""
    for index, first in enumerate(forces):
        for second in forces[index + 1:]:
            lengths = float(np.linalg.norm(first)), float(np.linalg.norm(second))
            if min(lengths) < NEGLIGIBLE_FORCE:
                continue
            cosine = float(np.dot(first, second)) / (lengths[0] * lengths[1])
            if math.acos(max(-1.0, min(1.0, cosine))) > min_angle and min(lengths) / max(lengths) >= FORCE_RATIO:
                return True
    return False


class GraspFix(Plugin):
    """Core of libgazebo_grasp_fix.so (GazeboGraspFix)."""
    GAZEBO_CLASS = "GazeboGraspFix"
    PARAMS = (
        Param("arm", str, None, "one or more: <arm_name>, <palm_link> (the link objects are attached to) and "
              "one or more <gripper_link> (the fingers)", warn_if_missing=False),
        Param("forces_angle_tolerance", float, 120.0, "degrees: two finger forces further apart than this grip",
              minimum=90.0, maximum=180.0),
        Param("update_rate", int, 5, "Hz of sim time: how often grips are checked", minimum=1, maximum=1000000),
        Param("max_grip_count", int, 10, "the most a gripped object's count rises to", minimum=1,
              maximum=MAX_COUNT),
        Param("grip_count_threshold", int, None, "above it, a gripped object is attached (absent: "
              "floor(max_grip_count / 2))", minimum=0, maximum=MAX_COUNT, warn_if_missing=False),
        non_negative("release_tolerance", float, 0.005, "m: a contact point moved this far from the object "
                     "releases it", maximum=1.0),
        Param("disable_collisions_on_attach", bool, False, "an attached object collides with nothing"),
    )

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        self.min_angle = math.radians(self.params["forces_angle_tolerance"])
        self.max_count = self.params["max_grip_count"]
        threshold = self.params["grip_count_threshold"]
        self.threshold = self.max_count // 2 if threshold is None else threshold
        self.arms = self._read_arms()
        self.timer = UpdateTimer(self.params["update_rate"], start=context.simulation.sim_time)
        self.joints = FixedJoints(context.simulation)
        self.counts: Dict[ObjectLink, int] = {}
        # attached object -> (arm, the touches that gripped it)
        self.attached: Dict[ObjectLink, Tuple[str, List[_Touch]]] = {}

    def _read_arms(self) -> Tuple[Arm, ...]:
        where = f"{self.context.where(self.element)}: {self.label}"
        links = self.context.robot.link_index
        arms: Dict[str, Arm] = {}
        for element in self.element.findall("arm"):
            name, palm = _text(element, "arm_name"), _text(element, "palm_link")
            fingers = tuple(_text(finger) for finger in element.findall("gripper_link"))
            if not (name and palm and fingers and all(fingers)):
                raise ConfigError(f"{where}: an <arm> needs <arm_name>, <palm_link> and at least one <gripper_link>")
            if name in arms:
                raise ConfigError(f"{where}: arm named {name} was already added, cannot add it twice")
            for link in (palm,) + fingers:
                if link not in links:
                    raise ConfigError(f"{where}: arm {name}: link {link} is not a link of model "
                                      f"'{self.context.model.name}' (it must not hang on a fixed joint; links there "
                                      f"are: {', '.join(sorted(links))})")
            arms[name] = Arm(name, palm, fingers)
        if not arms:
            raise ConfigError(f"{where}: cannot load the GazeboGraspFix without any <arm> declarations")
        return tuple(arms.values())

    # -- contacts ------------------------------------------------------------------------------------------------
    def _object_of(self, body: int, link: int) -> Optional[ObjectLink]:
        """(model, link) of a Bullet link another non-static model holds, from its collision's scoped name."""
        simulation = self.context.simulation
        scoped = simulation.engine.collision_names.get(body, {}).get(link)
        if scoped is None:
            return None
        model, link_name = scoped.split("::")[:2]
        world_model = simulation.world_models.get(model)
        if model == self.context.model.name or (world_model is not None and world_model.static):
            return None
        return model, link_name

    def _touches(self) -> Dict[ObjectLink, List[_Touch]]:
        simulation, robot = self.context.simulation, self.context.robot
        touches: Dict[ObjectLink, List[_Touch]] = {}
        for arm in self.arms:
            for finger in arm.fingers:
                points: Dict[ObjectLink, List[tuple]] = {}
                for point in simulation.engine.client.getContactPoints(bodyA=robot.body,
                                                                       linkIndexA=robot.link_index[finger]):
                    key = self._object_of(point[2], point[4])
                    if key is not None:
                        points.setdefault(key, []).append(point)
                if not points:
                    continue
                frame = robot.link_world_pose(finger)
                for key, found in points.items():
                    # Bullet's normal on B (the object) points toward A (the finger): it pushes the object away.
                    force = np.mean([-point[9] * np.asarray(point[7]) for point in found], axis=0)
                    contact = np.mean([point[5] for point in found], axis=0)
                    centre = simulation.link_state(f"{key[0]}::{key[1]}", "world")[0].position
                    touches.setdefault(key, []).append(_Touch(arm.name, finger, force, _in_frame(frame, contact),
                                                              _in_frame(frame, centre)))
        return touches

    # -- the update ----------------------------------------------------------------------------------------------
    def update(self, now: float):
        touches = self._touches()
        gripped = {key for key, found in touches.items() if grips([touch.force for touch in found], self.min_angle)}
        for key in gripped:
            self.counts[key] = min(self.counts.get(key, 0) + 1, self.max_count)
            if self.counts[key] > self.threshold and key not in self.attached:
                self._attach(key, touches[key])
        for key in [key for key in self.counts if key not in gripped]:
            self.counts[key] = max(self.counts[key] - 1, 0)
            if key in self.attached and self.counts[key] <= self.threshold and self._opened(key):
                self._release(key)
                self.counts[key] = 0

    def _attach(self, key: ObjectLink, touches: List[_Touch]):
        per_arm: Dict[str, int] = {}
        for touch in touches:
            per_arm[touch.arm] = per_arm.get(touch.arm, 0) + 1
        arm = next(arm for arm in self.arms if arm.name == max(per_arm, key=per_arm.get))
        if arm.name in [holder for holder, _ in self.attached.values()]:
            _logger.error(f"{self.label}: an object is already attached to gripper {arm.name}, so can't grasp "
                          f"'{key[0]}::{key[1]}'!")
            return
        error = self.joints.attach(arm.name, (self.context.model.name, arm.palm) + key,
                                   self.params["disable_collisions_on_attach"])
        if error:
            _logger.error(f"{self.label}: could not attach object {key[0]}::{key[1]} to gripper {arm.name}: {error}")
            return
        _logger.info(f"{self.label}: Attaching {key[0]}::{key[1]} to gripper {arm.name}.")
        self.attached[key] = (arm.name, [touch for touch in touches if touch.arm == arm.name])

    def _opened(self, key: ObjectLink) -> bool:
        """Whether a remembered contact point on a finger is now further from, or nearer to, the object's centre
        than when it gripped by more than release_tolerance."""
        robot, simulation = self.context.robot, self.context.simulation
        if not self.joints.holds(self.attached[key][0]):
            return True  # the object went (deleted) or the world was rebuilt
        centre = np.asarray(simulation.link_state(f"{key[0]}::{key[1]}", "world")[0].position)
        for touch in self.attached[key][1]:
            contact = np.asarray(compose(robot.link_world_pose(touch.finger),
                                         Pose(tuple(touch.contact), IDENTITY.orientation)).position)
            then = np.linalg.norm(touch.contact - touch.object_position)
            if abs(then - np.linalg.norm(contact - centre)) > self.params["release_tolerance"]:
                return True
        return False

    def _release(self, key: ObjectLink):
        arm, _ = self.attached.pop(key)
        self.joints.detach(arm)
        _logger.info(f"{self.label}: Detaching {key[0]}::{key[1]} from gripper {arm}.")

    def reset(self, now: float):
        super().reset(now)
        self.joints.release_all()
        self.attached.clear()
        self.counts.clear()

    def close(self):
        self.joints.release_all()


def _in_frame(frame: Pose, point) -> np.ndarray:
    """A world point in ``frame``'s coordinates."""
    return np.asarray(compose(inverse(frame), Pose(tuple(point), IDENTITY.orientation)).position)


def _text(element: ElementTree.Element, tag: Optional[str] = None) -> str:
    child = element if tag is None else element.find(tag)
    return (child.text or "").strip() if child is not None else ""
