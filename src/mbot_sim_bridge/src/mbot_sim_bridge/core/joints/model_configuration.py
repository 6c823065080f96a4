"""set_model_configuration (and spawn_model -J): a robot's joints set at once, exactly, from outside the physics."""
import math
from typing import Dict, List, Mapping, Sequence, Tuple

from ..description.robot_model import Joint
from ..errors import ModelError

# A continuous or unlimited joint's position beyond this (rad or m) leaves too few bits of a double for the
# 1e-9 steps controllers work at; a request for more is a mistake rather than a pose.
MAX_UNLIMITED_POSITION = 1e6


def requested_positions(joints: Mapping[str, Joint], movable_joints: Sequence[str], joint_names: Sequence[str],
                        positions: Sequence[float]) -> Tuple[Dict[str, float], List[str]]:
    """For a robot's ``joints`` (its URDF joints) of which ``movable_joints`` move in the physics: the
    positions to set by joint (URDF mimic followers the request does not name follow their leader), and the
    requested names the robot has no movable joint for (ignored, as Gazebo's Model::SetJointPositions ignores
    them). ModelError, setting nothing, for lists of different lengths or a position that is not finite or is
    outside the joint's limits."""
    if len(joint_names) != len(positions):
        raise ModelError("SetModelConfiguration: joint name and position list have different lengths")
    movable = set(movable_joints)
    wanted: Dict[str, float] = {}
    missing: List[str] = []
    for name, position in zip(joint_names, positions):
        if name not in movable:
            missing.append(name)
            continue
        joint = joints[name]
        if not math.isfinite(position):
            raise ModelError(f"SetModelConfiguration: joint '{name}': position {position} is not a finite number; "
                             "nothing was changed")
        limited = math.isfinite(joint.lower) and math.isfinite(joint.upper) and joint.type != "continuous"
        if limited and not joint.lower <= position <= joint.upper:
            raise ModelError(f"SetModelConfiguration: joint '{name}': position {position:g} is outside its limits "
                             f"[{joint.lower:g}, {joint.upper:g}]; nothing was changed")
        if not limited and abs(position) > MAX_UNLIMITED_POSITION:
            raise ModelError(f"SetModelConfiguration: joint '{name}': position {position:g} is outside "
                             f"±{MAX_UNLIMITED_POSITION:g}; nothing was changed")
        wanted[name] = float(position)
    for name in movable_joints:
        mimic = joints[name].mimic
        if name not in wanted and mimic is not None and mimic[0] in wanted:
            leader, multiplier, offset = mimic
            wanted[name] = multiplier * wanted[leader] + offset
    return wanted, missing
