"""~model_states, as gazebo_ros publishes it while subscribed: every model's pose and twist.

genpy builds and serializes a message object per model, which for a world of thousands of static models
costs more than the physics. Here the serialized form is kept in numpy arrays: static models' rows are
written when the set of models or a static pose changes, and only the moving models' rows each time.
"""
import struct

import numpy as np
from gazebo_msgs.msg import ModelStates

from .plugins import loop_publisher

WIRE_FLOAT = np.dtype("<f8")  # ROS float64 on the wire; filled in place, so serializing needs no conversion

def serialized_names(names) -> bytes:
    """A ROS string[]: its length, then each string's byte length and bytes (little-endian uint32)."""
    encoded = [name.encode() for name in names]
    return struct.pack("<I", len(encoded)) + b"".join(struct.pack("<I", len(name)) + name for name in encoded)


def serialized(names_bytes: bytes, poses: np.ndarray, twists: np.ndarray) -> bytes:
    """ModelStates on the wire: name[], then Pose[] (x y z, qx qy qz qw) and Twist[] (linear, angular); the
    arrays are little-endian float64 (WIRE_FLOAT)."""
    count = struct.pack("<I", len(poses))
    return b"".join((names_bytes, count, poses.tobytes(), count, twists.tobytes()))


class _Serialized(ModelStates):
    """A ModelStates whose bytes are already made."""

    __slots__ = ("raw",)

    def serialize(self, buff):
        buff.write(self.raw)


class ModelStatesPublisher:
    def __init__(self, sim):
        self.sim = sim
        self.publisher = loop_publisher("~model_states", ModelStates)
        self._version = None
        self._names = []
        self._moving = []  # (row, name) of the models whose pose can change by itself
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
        message = _Serialized()
        message.raw = serialized(self._names_bytes, self._poses, self._twists)
        self.publisher.publish(message)

    def _rebuild(self):
        sim = self.sim
        self._version = sim.version
        self._names = sim.model_names()
        self._names_bytes = serialized_names(self._names)
        self._poses = np.zeros((len(self._names), 7), WIRE_FLOAT)
        self._twists = np.zeros((len(self._names), 6), WIRE_FLOAT)
        static = {name for name, model in sim.world_models.items() if model.static}
        self._moving = [(row, name) for row, name in enumerate(self._names) if name not in static]
        for row, name in enumerate(self._names):
            self._fill(row, name)

    def _fill(self, row: int, name: str):
        engine = self.sim.engine
        pose = engine.model_pose(name)
        self._poses[row, :3], self._poses[row, 3:] = pose.position, pose.orientation
        linear, angular = engine.model_velocity(name)
        self._twists[row, :3], self._twists[row, 3:] = linear, angular
