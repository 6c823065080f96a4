"""Links of two models joined where they are by a PyBullet fixed constraint, as Gazebo's grasp plugins join them
with a joint: what the link attacher and the grasp fix share."""
from dataclasses import dataclass
from typing import Dict, Hashable, Optional, Tuple

import pybullet

from ..geometry import Pose, compose, inverse

# The most force (N) a joint applies to hold the links together: far beyond what any gripper carries, and the
# engine's bound on efforts.
MAX_HOLDING_FORCE = 1.0e5
# PyBullet's collision filter of a dynamic link (Bullet's DefaultFilter group, AllFilter mask).
_DYNAMIC_GROUP, _ALL_MASK = 1, -1

BulletLink = Tuple[int, int]  # (body, link index; -1 for the base)


@dataclass(frozen=True)
class _Joint:
    constraint: int
    models: Tuple[str, str]
    bodies: Tuple[int, int]
    rebuild: int  # the engine's rebuild count when it was made: after a rebuild it is gone
    silenced: Tuple[BulletLink, ...]  # the second link's Bullet links, colliding with nothing while attached


class FixedJoints:
    """Fixed constraints by key, each joining (model 1, link 1) to (model 2, link 2)."""

    def __init__(self, simulation):
        self.simulation = simulation
        self._joints: Dict[Hashable, _Joint] = {}

    def holds(self, key: Hashable) -> bool:
        """Whether the joint ``key`` holds; one whose models were rebuilt (reset_simulation, a NaN state) or
        deleted went with them, and is forgotten."""
        joint = self._joints.get(key)
        if joint is not None and not self._present(joint):
            del self._joints[key]
            joint = None
        return joint is not None

    def bullet_link(self, model: str, link: str) -> Tuple[Optional[BulletLink], str]:
        """(the Bullet link of a model's link, "") or (None, upstream's error)."""
        simulation = self.simulation
        if model not in simulation.model_names():
            return None, f"{model} model was not found"
        if link not in simulation.link_names(model):
            return None, f"{link} link was not found"
        if model in simulation.models:
            robot = simulation.models[model].robot
            return (robot.body, robot.link_index[link]), ""
        return (simulation.engine.body_of(model), -1), ""  # a world model is one body

    def _com_pose(self, link: BulletLink) -> Pose:
        client, (body, index) = self.simulation.engine.client, link
        if index < 0:
            position, orientation = client.getBasePositionAndOrientation(body)
        else:
            position, orientation = client.getLinkState(body, index)[:2]
        return Pose(tuple(position), tuple(orientation))

    def attach(self, key: Hashable, names: Tuple[str, str, str, str], silence_second: bool = False) -> str:
        """Join the links where they are now; "" when done, else why not (the world unchanged). With
        ``silence_second``, the second link collides with nothing until the joint is released."""
        model_1, link_1, model_2, link_2 = names
        first, error = self.bullet_link(model_1, link_1)
        if first is None:
            return error
        second, error = self.bullet_link(model_2, link_2)
        if second is None:
            return error
        if first == second:
            return f"link {link_1} of {model_1} cannot be attached to itself"
        child_in_parent = compose(inverse(self._com_pose(first)), self._com_pose(second))
        engine = self.simulation.engine
        client = engine.client
        constraint = client.createConstraint(first[0], first[1], second[0], second[1], pybullet.JOINT_FIXED,
                                             (0.0, 0.0, 0.0), child_in_parent.position, (0.0, 0.0, 0.0),
                                             child_in_parent.orientation)
        client.changeConstraint(constraint, maxForce=MAX_HOLDING_FORCE)
        silenced = self._collision_links(model_2, second) if silence_second else ()
        for body, index in silenced:
            client.setCollisionFilterGroupMask(body, index, 0, 0)
        self._joints[key] = _Joint(constraint, (model_1, model_2), (first[0], second[0]), engine.rebuilds, silenced)
        return ""

    def _collision_links(self, model: str, link: BulletLink) -> Tuple[BulletLink, ...]:
        """The Bullet links holding a link's collisions: a robot's own; all of a world model's body (its
        collisions are links of their own on it)."""
        if model in self.simulation.models:
            return (link,)
        body = link[0]
        return tuple((body, index) for index in range(-1, self.simulation.engine.client.getNumJoints(body)))

    def _present(self, joint: _Joint) -> bool:
        """Whether the joint's models are still those it joined (not rebuilt, deleted or replaced)."""
        engine = self.simulation.engine
        return joint.rebuild == engine.rebuilds and all(
            model in engine.model_names() and engine.body_of(model) == body
            for model, body in zip(joint.models, joint.bodies))

    def detach(self, key: Hashable) -> bool:
        """Release the joint ``key``; False when there is none. PyBullet removed it with a model of it."""
        joint = self._joints.pop(key, None)
        if joint is None:
            return False
        if self._present(joint):
            client = self.simulation.engine.client
            client.removeConstraint(joint.constraint)
            for body, index in joint.silenced:
                client.setCollisionFilterGroupMask(body, index, _DYNAMIC_GROUP, _ALL_MASK)
        return True

    def release_model(self, name: str):
        """Release every joint holding model ``name`` (it is about to go)."""
        for key in [key for key, joint in self._joints.items() if name in joint.models]:
            self.detach(key)

    def release_all(self):
        for key in list(self._joints):
            self.detach(key)
