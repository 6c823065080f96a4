"""A pick and place for the six-joint arm (arm_description) as joint-space waypoints: the gripper pointing straight
down, the box between the fingers, lifted, carried and set down. The demo (``./mbot demo --pick``) sends it
through the trajectory and gripper actions; the bridge's grasp tests run it on the core controllers.

The arm is planar but for its pan joint (shoulder_lift, elbow and wrist_1 turn about y), so a grasp point at
radius r and height z is a two-link problem for the wrist_1 joint straight above it, wrist_1 pointing the tool
down: lift + elbow + wrist_1 = pi. The lengths come from the arm's own YAML, as the xacro reads them."""
import math
import os
from dataclasses import dataclass
from typing import List, Sequence, Tuple

import rospkg
import yaml

JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint")
# gripper_macro.xacro: the fingers' joints sit 0.03 m beyond tool0 and the fingers are 0.06 m long. The grasp
# point is 0.075 m beyond tool0, 1.5 cm short of the fingertips, so a 4 cm box's base clears them by 5 mm.
GRASP_DEPTH = 0.075  # m, tool0 to the grasp point
OPEN = 0.035  # m, each finger from the centre line
APPROACH = 0.1  # m, above the grasp point before going down to it
# The arm's pace: a 0.1 m approach or a 0.2 m lift in a second, the 0.3 m carry in 1.5 s (at most about
# 0.4 m/s and 90 degrees/s per joint, half the joints' limits).
APPROACH_TIME, LIFT_TIME, CARRY_TIME = 1.0, 1.0, 1.5


@dataclass(frozen=True)
class ArmGeometry:
    shoulder_height: float  # the shoulder_lift axis above the base
    upper_arm: float
    forearm: float
    wrist_to_grasp: float  # wrist_1's axis to the grasp point, the tool pointing down

    @classmethod
    def from_description(cls) -> "ArmGeometry":
        config = os.path.join(rospkg.RosPack().get_path("arm_description"), "config")
        with open(os.path.join(config, "kinematics.yaml")) as stream:
            kinematics = yaml.safe_load(stream)["kinematics"]
        with open(os.path.join(config, "physical_parameters.yaml")) as stream:
            tool = yaml.safe_load(stream)["cylinder"]["wrist_3"]["length"]
        return cls(kinematics["shoulder"]["z"] + kinematics["upper_arm"]["z"], kinematics["forearm"]["z"],
                   kinematics["wrist_1"]["z"],
                   kinematics["wrist_2"]["z"] + kinematics["wrist_3"]["z"] + tool + GRASP_DEPTH)

    def joints_for(self, x: float, y: float, z: float) -> Tuple[float, ...]:
        """Joint positions putting the grasp point at (x, y, z) in the base frame, the tool pointing down and
        the fingers closing along the horizontal normal to the reach."""
        reach, height = math.hypot(x, y), z + self.wrist_to_grasp - self.shoulder_height
        cosine = (reach ** 2 + height ** 2 - self.upper_arm ** 2 - self.forearm ** 2) / (
            2.0 * self.upper_arm * self.forearm)
        if not -1.0 <= cosine <= 1.0:
            raise ValueError(f"({x:.3f}, {y:.3f}, {z:.3f}) is out of the arm's reach")
        elbow = math.acos(cosine)
        lift = math.atan2(reach, height) - math.atan2(self.forearm * math.sin(elbow),
                                                       self.upper_arm + self.forearm * math.cos(elbow))
        return (math.atan2(y, x), lift, elbow, math.pi - lift - elbow, 0.0, 0.0)


@dataclass(frozen=True)
class Step:
    """One step of the pick: a move through joint-space waypoints ((seconds, positions), ...) or a gripper
    command (``gripper`` the fingers' opening, with ``max_effort``)."""
    name: str
    waypoints: Sequence[Tuple[float, Tuple[float, ...]]] = ()
    gripper: float = None
    max_effort: float = 0.0


def pick_and_place(geometry: ArmGeometry, box: Sequence[float], target: Sequence[float], lift: float = 0.2,
                   max_effort: float = 20.0) -> List[Step]:
    """The steps taking a box whose centre is at ``box`` to ``target`` (base frame): open, approach from above,
    close, lift by ``lift``, carry, set down, open, withdraw."""
    above_box = geometry.joints_for(box[0], box[1], box[2] + APPROACH)
    above_target = geometry.joints_for(target[0], target[1], target[2] + lift)
    return [Step("open", gripper=OPEN, max_effort=max_effort),
            Step("approach", ((2.0, above_box), (2.0 + APPROACH_TIME, geometry.joints_for(*box)))),
            Step("close", gripper=0.0, max_effort=max_effort),
            Step("lift", ((LIFT_TIME, geometry.joints_for(box[0], box[1], box[2] + lift)),)),
            Step("carry", ((CARRY_TIME, above_target),)),
            Step("set down", ((LIFT_TIME, geometry.joints_for(*target)),)),
            Step("release", gripper=OPEN, max_effort=max_effort),
            Step("withdraw", ((APPROACH_TIME, geometry.joints_for(target[0], target[1], target[2] + APPROACH)),))]
