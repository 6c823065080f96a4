"""``libgazebo_ros_bumper.so`` on ``<sensor type="contact">`` without ROS (gazebo_plugins noetic-devel
``gazebo_ros_bumper.cpp`` over Gazebo's ContactSensor).

At the sensor's update_rate, one state per pair of collisions in contact: ``collision1_name`` is the sensor's
collision and ``collision2_name`` the other, both as Gazebo names them (``model::link::collision``; a URDF
link's collisions are named as sdformat names them, see ``RobotModel.collision_names``). Per contact point:
the position (world frame), the normal pointing towards collision1, the penetration depth, and the wrench on
collision1's body (world frame; torque about its centre of mass, as Gazebo's body_1_wrench). The
``frameName`` only labels the header (upstream's frame transform is commented out).

The sensor's ``<contact><collision>`` must name a collision of its link; Gazebo then reports nothing, silently,
when it does not (the usual "bumper sees no contact" trap), the bridge says so once with the names there are.
Bullet reports contacts per link, not per collision, so when several collisions are lumped into the sensor's
link (a bumper plate on a fixed joint), a contact point counts as the collision whose box (in the link frame)
it lies nearest to.
"""
from typing import List, NamedTuple, Optional

import numpy as np

from .. import names
from ..clock import UpdateTimer
from ..geometry import IDENTITY, Pose, Vector, compose, inverse
from ..log import get_logger, warn_once
from ..params import Param, PluginParams, rate
from ..plugin import Plugin
from .sensor_elements import sensor_label

_log = get_logger(__name__)



class ContactPoint(NamedTuple):
    position: Vector
    normal: Vector
    depth: float
    force: Vector
    torque: Vector


class CollisionContact(NamedTuple):
    collision1: str
    collision2: str
    points: List[ContactPoint]


class Bumper(Plugin):
    """Core of libgazebo_ros_bumper.so (GazeboRosBumper)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosBumper"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("bumperTopicName", str, "bumper_states", "gazebo_msgs/ContactsState", warn_if_missing=False),
        Param("frameName", str, "world", "frame_id of the header (the values stay in the world frame)",
              warn_if_missing=False),
    )
    IGNORED_TAGS = ("alwaysOn", "updateRate")
    SENSOR_TYPES = ("contact",)
    SENSOR_PARAMS = (
        rate("update_rate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
        Param("contact/collision", str, None, "the link's collision reported", required=True),
    )

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        self.params = self.read_params()
        robot = context.robot
        name, where, label = sensor_label(sensor, "contact sensor", context.link, robot.model.document)
        sensor_values = PluginParams(sensor, label, where=where, check_unknown=False).read(self.SENSOR_PARAMS)
        self.link = robot.model.lumped_into[context.link][0]
        self.link_index = robot.link_index[self.link]
        collision = sensor_values["contact/collision"]
        self.boxes = robot.model.collision_boxes().get(self.link, [])
        known = [box_name for box_name, _, _ in self.boxes]
        self.collision_index = known.index(collision) if collision in known else None
        self.collision_name: Optional[str] = f"{robot.name}::{self.link}::{collision}" if collision in known else None
        if self.collision_name is None:
            warn_once(_log, f"{where}: {label}: <contact><collision> '{collision}' is not a collision of link "
                            f"'{self.link}' ({', '.join(known) or 'it has none'}); as in Gazebo, no contact will be "
                            "reported")
        self.timer = UpdateTimer(sensor_values["update_rate"], start=context.simulation.sim_time)
        self.latest: List[CollisionContact] = []

    def update(self, now: float):
        self.latest = self.contacts() if self.collision_name is not None else []

    def contacts(self) -> List[CollisionContact]:
        robot = self.context.robot
        engine = self.context.simulation.engine
        client = robot.client
        if self.link_index == -1:
            centre = client.getBasePositionAndOrientation(robot.body)[0]
        else:
            centre = client.getLinkState(robot.body, self.link_index)[0]
        centre = np.asarray(centre)
        link_pose = robot.body_link_pose(self.link)  # the frame collision_boxes are given in
        pairs = {}
        points = [point for index in robot.bullet_links(self.link)
                  for point in client.getContactPoints(bodyA=robot.body, linkIndexA=index)]
        for point in points:
            body, link = point[2], point[4]
            if body == robot.body:
                continue  # Gazebo's robots do not self-collide by default
            if len(self.boxes) > 1 and self._nearest_box(link_pose, point[5]) != self.collision_index:
                continue
            other = engine.collision_names.get(body, {}).get(link, f"body {body}::link {link}::collision")
            normal = np.asarray(point[7])  # Bullet's normal on B points towards A, as Gazebo's towards collision1
            position = (np.asarray(point[5]) + np.asarray(point[6])) / 2.0
            force = point[9] * normal + point[10] * np.asarray(point[11]) + point[12] * np.asarray(point[13])
            torque = np.cross(position - centre, force)
            pairs.setdefault(other, []).append(ContactPoint(tuple(position), tuple(normal), max(0.0, -point[8]),
                                                            tuple(force), tuple(torque)))
        return [CollisionContact(self.collision_name, other, points) for other, points in sorted(pairs.items())]

    def _nearest_box(self, link_pose: Pose, world_point) -> int:
        """Index of the collision whose box the point (on the robot) lies in or nearest to."""
        local = compose(inverse(link_pose), Pose(tuple(world_point), IDENTITY.orientation)).position
        distances = []
        for _, pose, half in self.boxes:
            inside = compose(inverse(pose), Pose(local, IDENTITY.orientation)).position
            outside = np.maximum(np.abs(inside) - np.asarray(half), 0.0)
            distances.append(float(np.linalg.norm(outside)))
        return int(np.argmin(distances))
