"""``libhector_gazebo_ros_magnetic.so`` without ROS (hector_gazebo_plugins melodic-devel ``gazebo_ros_magnetic.cpp``).

The earth's field in the world, from ``magnitude``, ``referenceHeading`` ψ, ``declination`` δ and
``inclination`` ι (degrees), exactly as upstream sets it:

    (m·cos ι·cos(ψ − δ),  m·cos ι·sin(ψ − δ),  −m·sin ι)

and on each update that vector in the body's frame through the sensor model (the unprefixed tags, as the GPS's
position), published as geometry_msgs/Vector3Stamped, or sensor_msgs/MagneticField with
``useMagneticFieldMsgs``. frame_id is ``frameId``, by default the bodyName.
"""
import math
from typing import NamedTuple, Optional, Tuple

import numpy as np

from .. import names
from ..geometry import rotation_matrix
from .hector_plugin import HECTOR_UPDATE_PARAMS, HectorUpdates, body_link, update_timer, warn_world_coordinates
from .hector_sensor_model import SensorModel, sensor_model_params
from ..params import ERROR_MODEL_LIMIT, Param, non_negative, rate
from ..plugin import Plugin


class MagneticReading(NamedTuple):
    stamp: float
    field: Tuple[float, float, float]


class HectorMagnetic(HectorUpdates, Plugin):
    """Core of libhector_gazebo_ros_magnetic.so (hector's GazeboRosMagnetic)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosMagnetic"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("topicName", str, "magnetic", "geometry_msgs/Vector3Stamped (or MagneticField)", warn_if_missing=False),
        Param("bodyName", str, None, "link measured; absent: the model's root link", warn_if_missing=False),
        Param("frameId", str, None, "frame_id (default: bodyName)", warn_if_missing=False),
        non_negative("magnitude", float, 1.0, "field strength (the message's unit)", warn_if_missing=False,
                     maximum=ERROR_MODEL_LIMIT),
        Param("referenceHeading", float, 0.0, "degrees clockwise from north of the world's x axis",
              warn_if_missing=False),
        Param("declination", float, 0.0, "degrees", warn_if_missing=False),
        Param("inclination", float, 60.0, "degrees below the horizon", warn_if_missing=False),
        Param("useMagneticFieldMsgs", bool, False, "sensor_msgs/MagneticField instead of Vector3Stamped",
              warn_if_missing=False),
        Param("useWorldSphericalCoordinates", bool, False, "true: not emulated, referenceHeading applies",
              warn_if_missing=False),
        rate("updateRate", 0.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
        *HECTOR_UPDATE_PARAMS,
        *sensor_model_params("", 3, "field"),
    )

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        where = f"{context.where(element)}: {self.label}"
        warn_world_coordinates(params, where, "referenceHeading")
        self.link = body_link(context, element, self.label, params["bodyName"])
        self.frame_id = params["frameId"] if params["frameId"] is not None else (params["bodyName"] or self.link)
        heading, declination, inclination = (math.radians(params[tag]) for tag in
                                             ("referenceHeading", "declination", "inclination"))
        magnitude = params["magnitude"]
        self.world_field = np.array([magnitude * math.cos(inclination) * math.cos(heading - declination),
                                     magnitude * math.cos(inclination) * math.sin(heading - declination),
                                     -magnitude * math.sin(inclination)])
        self.model = SensorModel.from_params(params, "", 3, context.random_stream(element.get("name") or "magnetic"),
                                             where)
        self.sensor_models = (self.model,)
        self.timer = update_timer(params, context.simulation.sim_time)
        self.latest: Optional[MagneticReading] = None

    def update(self, now: float):
        dt = self.elapsed(now)
        orientation = self.context.robot.link_world_pose(self.link).orientation
        body_field = np.asarray(rotation_matrix(orientation)).T @ self.world_field
        self.latest = MagneticReading(now, tuple(float(value) for value in self.model(body_field, dt)))
