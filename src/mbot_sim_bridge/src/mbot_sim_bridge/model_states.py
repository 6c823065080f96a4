"""~model_states and ~link_states, as gazebo_ros publishes them while subscribed: every model's (every link's)
pose and twist.

genpy builds and serializes a message object per model, which for a world of thousands of static models
costs more than the physics. Here the serialized form is kept in numpy arrays: static models' rows are
written when the set of models or a static pose changes, and only the moving models' rows each time.
"""
import struct

import numpy as np
from gazebo_msgs.msg import LinkStates, ModelStates

from .plugins import loop_publisher

WIRE_FLOAT = np.dtype("<f8")  # ROS float64 on the wire; filled in place, so serializing needs no conversion

def serialized_names(names) -> bytes:
    """A ROS string[]: its length, then each string's byte length and bytes (little-endian uint32)."""
    encoded = [name.encode() for name in names]
    return struct.pack("<I", len(encoded)) + b"".join(struct.pack("<I", len(name)) + name for name in encoded)


def serialized(names_bytes: bytes, poses: np.ndarray, twists: np.ndarray) -> bytes:
    """ModelStates (and LinkStates, the same fields) on the wire: name[], then Pose[] (x y z, qx qy qz qw) and
    Twist[] (linear, angular); the arrays are little-endian float64 (WIRE_FLOAT)."""
    count = struct.pack("<I", len(poses))
    return b"".join((names_bytes, count, poses.tobytes(), count, twists.tobytes()))


class _SerializedModelStates(ModelStates):
    """A ModelStates whose bytes are already made."""

    __slots__ = ("raw",)

    def serialize(self, buff):
        buff.write(self.raw)


class _SerializedLinkStates(LinkStates):
    """A LinkStates whose bytes are already made."""

    __slots__ = ("raw",)

    def serialize(self, buff):
        buff.write(self.raw)


class ModelStatesPublisher:
    TOPIC, TYPE, SERIALIZED = "~model_states", ModelStates, _SerializedModelStates

    def __init__(self, sim):
        self.sim = sim
        self.publisher = loop_publisher(self.TOPIC, self.TYPE)
        self._version = None
        self._names = []
        self._moving = []  # (row, name) of the entities whose pose can change by itself
        self._poses = np.zeros((0, 7), WIRE_FLOAT)
        self._twists = np.zeros((0, 6), WIRE_FLOAT)
        self._names_bytes = b""

    def publish(self):
        if self.publisher.get_num_connections() == 0:
            return
        if self._version != self.sim.version:
            self._rebuild()
        for row, name in self._moving:
            self._fill(row, name)
        message = self.SERIALIZED()
        message.raw = serialized(self._names_bytes, self._poses, self._twists)
        self.publisher.publish(message)

    def entities(self):
        """(name, static) of every entity, in the message's order."""
        static = {name for name, model in self.sim.world_models.items() if model.static}
        return [(name, name in static) for name in self.sim.model_names()]

    def state(self, name: str):
        """(pose, linear, angular) of an entity in the world."""
        return self.sim.engine.model_pose(name), *self.sim.engine.model_velocity(name)

    def _rebuild(self):
        self._version = self.sim.version
        entities = self.entities()
        self._names = [name for name, _ in entities]
        self._names_bytes = serialized_names(self._names)
        self._poses = np.zeros((len(self._names), 7), WIRE_FLOAT)
        self._twists = np.zeros((len(self._names), 6), WIRE_FLOAT)
        self._moving = [(row, name) for row, (name, static) in enumerate(entities) if not static]
        for row, name in enumerate(self._names):
            self._fill(row, name)

    def _fill(self, row: int, name: str):
        pose, linear, angular = self.state(name)
        self._poses[row, :3], self._poses[row, 3:] = pose.position, pose.orientation
        self._twists[row, :3], self._twists[row, 3:] = linear, angular


class LinkStatesPublisher(ModelStatesPublisher):
    """Every link the physics has (a robot's after fixed-joint lumping, as Gazebo's), named "model::link"."""
    TOPIC, TYPE, SERIALIZED = "~link_states", LinkStates, _SerializedLinkStates

    def entities(self):
        return [(f"{model}::{link}", static) for model, static in super().entities()
                for link in self.sim.link_names(model)]

    def state(self, name: str):
        return self.sim.link_state(name, "")
