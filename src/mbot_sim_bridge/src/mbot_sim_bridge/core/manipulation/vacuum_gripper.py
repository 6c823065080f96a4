"""``libgazebo_ros_vacuum_gripper.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_vacuum_gripper.cpp``).

Switched on and off by the ``on`` and ``off`` services (std_srvs/Empty, in the robot namespace). While on, before
every physics step, each other model whose frame lies within REACH of the ``bodyName`` link's frame is pulled as
upstream pulls it: it takes the link's linear and angular velocity, a force of 1/distance (at most MAX_FORCE N)
pushes it toward the link, and within SNAP it is moved onto the link's origin, its orientation kept. The force's
direction is upstream's pose difference, the link's position minus the object's rotated into the object's frame,
applied in the world frame. ``grasping`` (std_msgs/Bool on ``topicName``) says whether anything was pulled.
Upstream's three figures are fixed in its code, as here. Upstream walks every link of every model; here each
model moves as a whole through its frame (objects picked are one-link models), static models not at all.
"""
import math
from typing import Tuple

from .. import names
from ..body_wrenches import ZERO
from ..clock import UpdateTimer
from ..geometry import Pose, rotate
from ..log import get_logger
from ..params import Param
from ..plugin import Plugin
from . import body_link
from ..sensors.body_sensors import IDLE_PERIOD

_logger = get_logger(__name__)
REACH, SNAP, MAX_FORCE = 0.05, 0.01, 20.0  # m, m, N


class VacuumGripper(Plugin):
    """Core of libgazebo_ros_vacuum_gripper.so (GazeboRosVacuumGripper)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosVacuumGripper"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic and the on/off services", warn_if_missing=False),
        Param("bodyName", str, None, "the link that pulls (the pad)", required=True),
        Param("topicName", str, None, "std_msgs/Bool: whether something is pulled", required=True),
    )
    needs_every_step = True

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        self.link = body_link(self)
        self.timer = UpdateTimer(0.0, start=context.simulation.sim_time)
        self.on = False
        self.grasping = False

    def switch(self, on: bool) -> str:
        """The on or off service: what upstream logs."""
        if self.on == on:
            return f"gazebo_ros_vacuum_gripper: already status is '{'on' if on else 'off'}'"
        self.on = on
        return f"gazebo_ros_vacuum_gripper: status: {'off -> on' if on else 'on -> off'}"

    def _pulled(self):
        """(model name, its frame's pose, its distance) of every model within reach of the pad."""
        engine, own = self.context.engine, self.context.model.name
        pad = self.context.robot.link_world_pose(self.link).position
        for name in engine.model_names():
            if name == own or self._static(name):
                continue
            pose = engine.model_pose(name)
            distance = math.dist(pad, pose.position)
            if distance < REACH:
                yield name, pose, distance

    def _static(self, name: str) -> bool:
        world_model = self.context.simulation.world_models.get(name)
        return world_model is not None and world_model.static

    def on_step(self, step_size: float):
        self.grasping = False
        if not self.on:
            return
        engine, robot = self.context.engine, self.context.robot
        pad = robot.link_world_pose(self.link)
        linear, angular = robot.link_world_velocity(self.link)
        for name, pose, distance in list(self._pulled()):
            toward = self._toward(pad, pose)
            if distance < SNAP:
                pose = Pose(pad.position, pose.orientation)
            engine.set_model_state(name, pose, linear, angular)
            strength = min(1.0 / distance, MAX_FORCE) if distance > 0 else MAX_FORCE
            length = math.sqrt(sum(value * value for value in toward))
            force = tuple(strength * value / length for value in toward) if length > 0 else ZERO
            engine.apply_link_wrench(engine.body_of(name), -1, force, ZERO)
            self.grasping = True

    @staticmethod
    def _toward(pad: Pose, pose: Pose) -> Tuple[float, float, float]:
        """Upstream's ``(pad pose - object pose).Pos()``: the offset to the pad in the object's frame."""
        offset = tuple(a - b for a, b in zip(pad.position, pose.position))
        x, y, z, w = pose.orientation
        return rotate((-x, -y, -z, w), offset)

    def idle(self, now: float):
        """While nobody subscribes to ``grasping``, look only every IDLE_PERIOD (the pulling goes on each step)."""
        self.timer.period = IDLE_PERIOD

    def update(self, now: float):
        self.timer.period = 0.0

    def reset(self, now: float):
        super().reset(now)
        self.grasping = False
