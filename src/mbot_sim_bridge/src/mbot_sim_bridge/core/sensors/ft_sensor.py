"""``libgazebo_ros_ft_sensor.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_ft_sensor.cpp``).

Upstream publishes the joint's Joint::GetForceTorque(0).body2Force/body2Torque: the negated force and torque
the joint applies to its child link, the torque taken about the joint (the child link's origin), both in the
child link's frame; so a load hanging below the joint reads its weight, pointing down. Each of the six values
gets N(0, ``gaussianNoise``); ``updateRate`` 0 publishes every physics step.

PyBullet's joint reaction sensor gives the force but, for the torque, only its part along the joint's axis, so
the wrench is computed from the child's side instead, by Newton–Euler over the child link and every link below
it: F = Σ m(a − g) − the contact forces and applied wrenches on them, M about the joint likewise with
I·α + ω × I·ω, accelerations from the velocity change since the previous reading (zero for the first one, and
for the first after a reset or after nobody listened, while the bridge looks only every 50 ms). A fixed joint is
lumped away, as Gazebo lumps it, so a sensor on one is refused as Gazebo's "does not exist".
"""
from typing import List, NamedTuple, Optional, Tuple

import numpy as np

from .. import names
from ..clock import UpdateTimer
from ..errors import ConfigError
from .body_sensors import IDLE_PERIOD
from ..geometry import Vector, rotation_matrix
from ..params import ERROR_MODEL_LIMIT, Param, non_negative, rate
from ..plugin import Plugin



class JointWrench(NamedTuple):
    stamp: float
    force: Vector  # child link frame
    torque: Vector


class FTSensor(Plugin):
    """Core of libgazebo_ros_ft_sensor.so (GazeboRosFT)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosFT"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("jointName", str, None, "the movable joint measured", required=True),
        Param("topicName", str, None, "geometry_msgs/WrenchStamped", required=True),
        non_negative("gaussianNoise", float, 0.0, "stddev on each of the six values", maximum=ERROR_MODEL_LIMIT),
        rate("updateRate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
    )
    IGNORED_TAGS = ("alwaysOn",)

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        robot = context.robot
        joint = self.params["jointName"]
        if joint not in robot.joint_index:
            movable = ", ".join(robot.movable_joints) or "none"
            kind = robot.model.joints[joint].type if joint in robot.model.joints else None
            why = "is a fixed joint, lumped away as Gazebo lumps it" if kind == "fixed" else "does not exist"
            raise ConfigError(f"{context.where(element)}: {self.label}: jointName: {joint} {why} (movable joints: "
                              f"{movable})")
        self.joint = joint
        self.child_link = robot.model.joints[joint].child
        client, body = robot.client, robot.body
        self.child_index = robot.joint_index[joint]
        parents = {index: client.getJointInfo(body, index)[16] for index in range(client.getNumJoints(body))}
        self.links = [index for index in parents if self._below(index, parents)]
        dynamics = [client.getDynamicsInfo(body, index) for index in self.links]
        self.masses = np.array([info[0] for info in dynamics])
        self.inertia_diagonals = np.array([info[2] for info in dynamics])
        self.gravity = np.asarray(context.simulation.engine.physics.gravity, dtype=float)
        self.rng = context.random_stream(element.get("name") or "ft_sensor")
        self.timer = UpdateTimer(self.params["updateRate"], start=context.simulation.sim_time)
        self.period = self.timer.period
        # (sim time, linear and angular velocities of the child side's links) at the previous reading.
        self._previous: Optional[Tuple[float, np.ndarray, np.ndarray]] = None
        self.latest: Optional[JointWrench] = None

    def _below(self, index: int, parents) -> bool:
        while index != -1:
            if index == self.child_index:
                return True
            index = parents[index]
        return False

    def _states(self):
        robot = self.context.robot
        return robot.client.getLinkStates(robot.body, self.links, computeLinkVelocity=1,
                                          computeForwardKinematics=1)

    def idle(self, now: float):
        """While nobody listens, look only every IDLE_PERIOD; the next reading starts its accelerations afresh."""
        self.timer.period = max(self.period, IDLE_PERIOD)
        self._previous = None

    def reset(self, now: float):
        super().reset(now)
        self._previous = None

    def wrench(self, now: float) -> Tuple[np.ndarray, np.ndarray]:
        """(force, torque about the joint) the joint applies to the child side, world frame."""
        robot = self.context.robot
        states = self._states()
        centres = np.array([state[0] for state in states])
        velocities = np.array([state[6] for state in states]), np.array([state[7] for state in states])
        linear, angular = np.zeros_like(centres), np.zeros_like(centres)
        if self._previous is not None and now > self._previous[0]:
            elapsed = now - self._previous[0]
            linear, angular = ((current - before) / elapsed for current, before in zip(velocities, self._previous[1:]))
        self._previous = (now, *velocities)
        omegas = velocities[1]
        joint_origin = np.asarray(robot.body_link_pose(self.child_link).position)  # the URDF frame: the joint's
        inertial = self.masses[:, np.newaxis] * (linear - self.gravity)
        force = inertial.sum(axis=0)
        torque = np.cross(centres - joint_origin, inertial).sum(axis=0)
        for state, diagonal, alpha, omega in zip(states, self.inertia_diagonals, angular, omegas):
            rotation = np.asarray(rotation_matrix(state[1]))
            inertia = rotation @ np.diag(diagonal) @ rotation.T
            torque += inertia @ alpha + np.cross(omega, inertia @ omega)
        for point, external in self._external_forces():
            force -= external
            torque -= np.cross(point - joint_origin, external)
        for point, external, external_torque in self._applied_wrenches(centres):
            force -= external
            torque -= np.cross(point - joint_origin, external) + external_torque
        return force, torque

    def _external_forces(self) -> List[Tuple[np.ndarray, np.ndarray]]:
        """(point, force) of every contact on the child side from outside the robot, world frame."""
        robot = self.context.robot
        contacts = []
        for index in self.links:
            for contact in robot.client.getContactPoints(bodyA=robot.body, linkIndexA=index):
                if contact[2] == robot.body:
                    continue  # the robot's own links act inside the measured side or through the joint
                # Force on A: the normal (contactNormalOnB points from B to A) and the two friction forces.
                force = (contact[9] * np.asarray(contact[7]) + contact[10] * np.asarray(contact[11])
                         + contact[12] * np.asarray(contact[13]))
                contacts.append((np.asarray(contact[5]), force))
        return contacts

    def _applied_wrenches(self, centres) -> List[Tuple[np.ndarray, np.ndarray, np.ndarray]]:
        robot, model = self.context.robot, self.context.model.name
        names_by_index = {index: name for name, index in robot.link_index.items()}
        wrenches = self.context.simulation.wrenches
        applied = []
        for centre, index in zip(centres, self.links):
            force, torque = wrenches.applied_to(model, names_by_index[index])
            if any(force) or any(torque):
                applied.append((centre, np.asarray(force), np.asarray(torque)))
        return applied

    def update(self, now: float):
        self.timer.period = self.period
        force, torque = self.wrench(now)
        rotation = np.asarray(rotation_matrix(self.context.robot.link_world_pose(self.child_link).orientation))
        # Gazebo's body2Force and body2Torque: negated, in the child link's frame.
        values = np.concatenate([rotation.T @ -force, rotation.T @ -torque])
        noise = self.params["gaussianNoise"]
        if noise:
            values = values + self.rng.normal(0.0, noise, 6)
        self.latest = JointWrench(now, tuple(values[:3].tolist()), tuple(values[3:].tolist()))
