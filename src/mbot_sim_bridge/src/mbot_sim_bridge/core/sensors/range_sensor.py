"""Range finders on a ray sensor: ``libgazebo_ros_range.so`` (gazebo_plugins noetic-devel
``gazebo_ros_range.cpp``) and hector's ``libhector_gazebo_ros_sonar.so`` (``gazebo_ros_sonar.cpp``).

Both report the smallest raw range over every ray of the sensor (the laser shape's: range_min plus the hit
distance, range_max when nothing is hit; the sensor's own noise and the ±inf of a LaserScan do not apply), and
``min_range``/``max_range`` are the sensor's ``<range>``. Then, only when that is below max_range:
- gazebo_ros_range adds N(0, gaussianNoise) and keeps it at most max_range; ``field_of_view`` is the ``fov``
  tag (not the rays' spread) and ``radiation`` "ultrasound" gives ULTRASOUND, anything else INFRARED; it
  publishes at the sensor's update_rate, throttled to ``updateRate``;
- hector's sonar passes it through its sensor model (``offset``, ``drift``, ``gaussianNoise``... as hector's
  IMU) and clamps it to [min_range, max_range]; ``field_of_view`` is the smaller of the horizontal and
  vertical spreads; it updates at its own ``updateRate`` (default 10 Hz), whatever the sensor's rate.
"""
from typing import NamedTuple, Optional

from .. import names
from ..clock import UpdateTimer
from ..hector.hector_plugin import HECTOR_UPDATE_PARAMS, HectorUpdates, update_timer
from ..hector.hector_sensor_model import SensorModel, sensor_model_params
from .lidar import RaySensor
from ..params import ERROR_MODEL_LIMIT, Param, non_negative, rate

ULTRASOUND, INFRARED = 0, 1  # sensor_msgs/Range radiation types


class RangeReading(NamedTuple):
    stamp: float
    range: float


class RangeSensor(RaySensor):
    """Core of libgazebo_ros_range.so (GazeboRosRange)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosRange"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("topicName", str, "/range", "sensor_msgs/Range", warn_if_missing=False),
        Param("frameName", str, "/world", "frame_id, resolved with the tf prefix", warn_if_missing=False),
        Param("radiation", str, "ultrasound", "ultrasound; anything else is infrared"),
        non_negative("fov", float, 0.05, "rad; the message's field_of_view"),
        non_negative("gaussianNoise", float, 0.0, "m; stddev added to a reading below max_range",
                     warn_if_missing=False, maximum=ERROR_MODEL_LIMIT),
        rate("updateRate", 0.0, "Hz throttle on top of the sensor's update_rate; 0 = none",
             warn_if_missing=False),
    )

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        self.radiation_type = ULTRASOUND if self.params["radiation"] == "ultrasound" else INFRARED
        rates = [rate for rate in (self.config.update_rate, self.params["updateRate"]) if rate > 0]
        self.timer = UpdateTimer(min(rates) if rates else 0.0, start=context.simulation.sim_time)
        self.noise_rng = context.random_stream(f"{self.config.sensor_name}/range")
        self.field_of_view = self.params["fov"]
        self.latest: Optional[RangeReading] = None

    def update(self, now: float):
        reading = float(self.raw_ranges().min())
        noise = self.params["gaussianNoise"]
        if reading < self.config.range_max:
            reading = min(reading + (self.noise_rng.normal(0.0, noise) if noise else 0.0), self.config.range_max)
        self.latest = RangeReading(now, reading)


class HectorSonar(HectorUpdates, RaySensor):
    """Core of libhector_gazebo_ros_sonar.so (hector's GazeboRosSonar)."""
    NAMESPACE_RULE = names.ROOT
    GAZEBO_CLASS = "GazeboRosSonar"
    PARAMS = (
        Param("robotNamespace", str, "", "namespace of the topic", warn_if_missing=False),
        Param("topicName", str, "sonar", "sensor_msgs/Range", warn_if_missing=False),
        Param("frameId", str, "/sonar_link", "frame_id, as given", warn_if_missing=False),
        rate("updateRate", 10.0, "Hz of sim time; 0 = every physics step", warn_if_missing=False),
        *HECTOR_UPDATE_PARAMS,
        *sensor_model_params("", 1, "range (m)"),
    )

    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        config = self.config
        self.radiation_type = ULTRASOUND
        self.field_of_view = min(abs(config.max_angle - config.min_angle),
                                 abs(config.vertical_max_angle - config.vertical_min_angle))
        where = f"{context.where(element)}: {self.label}"
        self.model = SensorModel.from_params(self.params, "", 1, context.random_stream(f"{config.sensor_name}/sonar"),
                                             where)
        self.sensor_models = (self.model,)
        self.timer = update_timer(self.params, context.simulation.sim_time)
        self.latest: Optional[RangeReading] = None

    def update(self, now: float):
        dt = self.elapsed(now)
        config = self.config
        reading = float(self.raw_ranges().min())
        if reading < config.range_max:
            reading = min(max(float(self.model(reading, dt)), config.range_min), config.range_max)
        self.latest = RangeReading(now, reading)
