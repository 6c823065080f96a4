"""``libhector_gazebo_ros_gps.so`` without ROS (hector_gazebo_plugins melodic-devel ``gazebo_ros_gps.cpp``).

The body's world position and velocity, each through a SensorModel (position: the unprefixed ``offset``,
``drift``, ``gaussianNoise``... tags; velocity: ``velocity*``), become a fix around the reference point on
the WGS84 ellipsoid exactly as upstream converts them: with the heading ψ (``referenceHeading``, degrees
clockwise from north, 0 = x points north)

    latitude  = lat₀ + ( cos ψ·x + sin ψ·y) / R_north · 180/π
    longitude = lon₀ − (−sin ψ·x + cos ψ·y) / R_east  · 180/π        (so at ψ = 0, +y is west)
    altitude  = alt₀ + z

with R_north and R_east the meridian and parallel radii at lat₀; the velocity is rotated the same way
(x north, y west, z up). The velocity model's drift is integrated into the position drift on each update.
The position covariance is diagonal (drift² + noise², COVARIANCE_TYPE_DIAGONAL_KNOWN). ``updateRate``
defaults to 4 Hz.
"""
import math
from typing import NamedTuple, Optional, Tuple


from .. import names
from .hector_plugin import HECTOR_UPDATE_PARAMS, HectorUpdates, body_link, update_timer, warn_world_coordinates
from .hector_sensor_model import SensorModel, sensor_model_params
from ..params import Param, rate
from ..plugin import Plugin

EQUATORIAL_RADIUS = 6378137.0
FLATTENING = 1.0 / 298.257223563
EXCENTRICITY2 = 2 * FLATTENING - FLATTENING * FLATTENING


class GpsReading(NamedTuple):
    stamp: float
    latitude: float
    longitude: float
    altitude: float
    velocity: Tuple[float, float, float]  # north, west, up
    position_covariance: Tuple[float, float, float]  # diagonal


def earth_radii(latitude_degrees: float) -> Tuple[float, float]:
    """(R_north, R_east) at a latitude: metres per radian of latitude and of longitude."""
    sin_latitude = math.sin(math.radians(latitude_degrees))
    temp = 1.0 / (1.0 - EXCENTRICITY2 * sin_latitude * sin_latitude)
    prime_vertical = EQUATORIAL_RADIUS * math.sqrt(temp)
    return prime_vertical * (1 - EXCENTRICITY2) * temp, prime_vertical * math.cos(math.radians(latitude_degrees))


class HectorGps(HectorUpdates, Plugin):
    """Core of libhector_gazebo_ros_gps.so (hector's GazeboRosGps)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosGps"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topics", warn_if_missing=False),
        Param("bodyName", str, None, "link measured; absent: the model's root link", warn_if_missing=False),
        Param("frameId", str, "/world", "frame_id of both messages", warn_if_missing=False),
        Param("topicName", str, "fix", "sensor_msgs/NavSatFix", warn_if_missing=False),
        Param("velocityTopicName", str, "fix_velocity", "geometry_msgs/Vector3Stamped (north, west, up)",
              warn_if_missing=False),
        Param("referenceLatitude", float, 49.9, "degrees", warn_if_missing=False, minimum=-90.0, maximum=90.0),
        Param("referenceLongitude", float, 8.9, "degrees", warn_if_missing=False, minimum=-180.0, maximum=180.0),
        Param("referenceHeading", float, 0.0, "degrees clockwise from north of the world's x axis",
              warn_if_missing=False),
        Param("referenceAltitude", float, 0.0, "m", warn_if_missing=False),
        Param("status", int, 0, "NavSatStatus status (0 = STATUS_FIX)", warn_if_missing=False, minimum=-128,
              maximum=127),
        Param("service", int, 0, "NavSatStatus service bits", warn_if_missing=False, minimum=0, maximum=65535),
        Param("useWorldSphericalCoordinates", bool, False, "true: not emulated, the reference tags apply",
              warn_if_missing=False),
        rate("updateRate", 4.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
        *HECTOR_UPDATE_PARAMS,
        *sensor_model_params("", 3, "position (m)"),
        *sensor_model_params("velocity", 3, "velocity (m/s)"),
    )

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.params = params = self.read_params()
        where = f"{context.where(element)}: {self.label}"
        warn_world_coordinates(params, where, "the reference tags")
        self.link = body_link(context, element, self.label, params["bodyName"])
        self.frame_id = params["frameId"]
        self.heading = math.radians(params["referenceHeading"])
        self.radius_north, self.radius_east = earth_radii(params["referenceLatitude"])
        rng = context.random_stream(element.get("name") or "hector_gps")
        self.position_model = SensorModel.from_params(params, "", 3, rng, where)
        self.velocity_model = SensorModel.from_params(params, "velocity", 3, rng, where)
        self.sensor_models = (self.position_model, self.velocity_model)
        self.timer = update_timer(params, context.simulation.sim_time)
        self.latest: Optional[GpsReading] = None

    def geodetic(self, position) -> Tuple[float, float, float]:
        """(latitude, longitude, altitude) of a world position, as upstream converts it, with the longitude
        wrapped into [-180, 180) as a receiver reports it (near a pole upstream's reached millions of degrees)."""
        x, y, z = position
        cos_h, sin_h = math.cos(self.heading), math.sin(self.heading)
        longitude = self.params["referenceLongitude"] - math.degrees((-sin_h * x + cos_h * y) / self.radius_east)
        return (self.params["referenceLatitude"] + math.degrees((cos_h * x + sin_h * y) / self.radius_north),
                (longitude + 180.0) % 360.0 - 180.0, self.params["referenceAltitude"] + z)

    def update(self, now: float):
        dt = self.elapsed(now)
        robot = self.context.robot
        velocity = self.velocity_model(robot.link_world_velocity(self.link)[0], dt)
        position = self.position_model(robot.link_world_pose(self.link).position, dt)
        self.position_model.current_drift = self.position_model.current_drift + dt * self.velocity_model.current_drift
        cos_h, sin_h = math.cos(self.heading), math.sin(self.heading)
        north_west_up = (cos_h * velocity[0] + sin_h * velocity[1], -sin_h * velocity[0] + cos_h * velocity[1],
                         velocity[2])
        model = self.position_model
        variance = tuple(model.drift ** 2 + model.gaussian_noise ** 2)
        self.latest = GpsReading(now, *self.geodetic(position), tuple(float(v) for v in north_west_up), variance)
