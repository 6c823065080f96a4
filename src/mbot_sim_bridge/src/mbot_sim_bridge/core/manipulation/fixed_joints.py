"""Links of two models joined where they are by a PyBullet fixed constraint, as Gazebo's grasp plugins join them
with a joint: what the link attacher and the grasp fix share."""
from typing import Dict, Hashable, Optional, Tuple

import pybullet

from ..geometry import Pose, compose, inverse

# The most force (N) a joint applies to hold the links together: far beyond what any gripper carries, below
# what would launch a body whose link was set elsewhere (the engine's effort bound).
MAX_HOLDING_FORCE = 1.0e5


class FixedJoints:
    """Fixed constraints by key, each joining (model 1, link 1) to (model 2, link 2)."""

    def __init__(self, simulation):
        self.simulation = simulation
        # key -> (constraint id, model 1, model 2, collisions disabled between (body, link) pairs or None)
        self._joints: Dict[Hashable, Tuple[int, str, str, Optional[Tuple[Tuple[int, int], Tuple[int, int]]]]] = {}

    def holds(self, key: Hashable) -> bool:
        return key in self._joints

    def _link(self, model: str, link: str) -> Tuple[Optional[Tuple[int, int]], str]:
        """((body, Bullet link index), "") of a model's link, or (None, upstream's error)."""
        simulation = self.simulation
        if model not in simulation.model_names():
            return None, f"{model} model was not found"
        if link not in simulation.link_names(model):
            return None, f"{link} link was not found"
        if model in simulation.models:
            robot = simulation.models[model].robot
            return (robot.body, robot.link_index[link]), ""
        return (simulation.engine.body_of(model), -1), ""  # a world model is one body

    def _com_pose(self, body: int, index: int) -> Pose:
        client = self.simulation.engine.client
        if index < 0:
            position, orientation = client.getBasePositionAndOrientation(body)
        else:
            position, orientation = client.getLinkState(body, index)[:2]
        return Pose(tuple(position), tuple(orientation))

    def attach(self, key: Hashable, names: Tuple[str, str, str, str], disable_collisions: bool = False) -> str:
        """Join the links where they are now; "" when done, else why not (the world unchanged)."""
        model_1, link_1, model_2, link_2 = names
        first, error = self._link(model_1, link_1)
        if first is None:
            return error
        second, error = self._link(model_2, link_2)
        if second is None:
            return error
        if first == second:
            return f"link {link_1} of {model_1} cannot be attached to itself"
        child_in_parent = compose(inverse(self._com_pose(*first)), self._com_pose(*second))
        client = self.simulation.engine.client
        constraint = client.createConstraint(first[0], first[1], second[0], second[1], pybullet.JOINT_FIXED,
                                             (0.0, 0.0, 0.0), child_in_parent.position, (0.0, 0.0, 0.0),
                                             child_in_parent.orientation)
        client.changeConstraint(constraint, maxForce=MAX_HOLDING_FORCE)
        pair = None
        if disable_collisions:
            pair = (first, second)
            client.setCollisionFilterPair(first[0], second[0], first[1], second[1], 0)
        self._joints[key] = (constraint, model_1, model_2, pair)
        return ""

    def detach(self, key: Hashable) -> bool:
        """Release the joint ``key``; False when there is none."""
        joint = self._joints.pop(key, None)
        if joint is None:
            return False
        constraint, _, _, pair = joint
        client = self.simulation.engine.client
        client.removeConstraint(constraint)
        if pair is not None:
            (body_1, link_1), (body_2, link_2) = pair
            client.setCollisionFilterPair(body_1, body_2, link_1, link_2, 1)
        return True

    def release_model(self, name: str):
        """Release every joint holding model ``name`` (it is about to go)."""
        for key in [key for key, (_, model_1, model_2, _) in self._joints.items() if name in (model_1, model_2)]:
            self.detach(key)

    def release_all(self):
        for key in list(self._joints):
            self.detach(key)

    def forget(self):
        """The world was built again without them: nothing to remove."""
        self._joints.clear()
