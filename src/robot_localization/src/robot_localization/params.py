"""ekf_localization_node's parameters, read and checked without ROS: upstream's names and defaults
(RosFilter::loadParams), one line naming the parameter for a bad value, one for a name upstream does not know or
this node does not support."""
import math
import re
from dataclasses import dataclass, field

import numpy as np

from .ekf import AX, DEFAULT_PROCESS_NOISE, STATE_NAMES, STATE_SIZE, VX, VYAW, X
from .estimator import Frames, Source

SENSOR_KINDS = ("odom", "pose", "twist", "imu")
SENSOR_SETTINGS = {
    "odom": {"config", "differential", "relative", "queue_size", "nodelay", "pose_rejection_threshold",
             "twist_rejection_threshold"},
    "pose": {"config", "differential", "relative", "queue_size", "nodelay", "rejection_threshold"},
    "twist": {"config", "queue_size", "nodelay", "rejection_threshold"},
    "imu": {"config", "differential", "relative", "queue_size", "nodelay", "pose_rejection_threshold",
            "twist_rejection_threshold", "linear_acceleration_rejection_threshold",
            "remove_gravitational_acceleration"},
}
# Upstream's names this node reads and ignores, with a warning: control input, the reset on a time jump, the
# debug file, and the services that go with them.
UNSUPPORTED = {"use_control", "stamped_control", "control_timeout", "control_config", "acceleration_limits",
               "acceleration_gains", "deceleration_limits", "deceleration_gains", "reset_on_time_jump",
               "disabled_at_startup", "debug", "debug_out_file",
               "permit_corrected_publication"}
UNSUPPORTED_SENSOR_SETTINGS = {"pose_use_child_frame"}
SENSOR_NAME = re.compile(r"^(odom|pose|twist|imu)(\d+)(?:_(.+))?$")
FRAME_PARAMETERS = ("map_frame", "odom_frame", "base_link_frame", "base_link_frame_output", "world_frame")
GLOBAL = {"frequency", "sensor_timeout", "two_d_mode", "publish_tf", "publish_acceleration", "invert_tf",
          "transform_time_offset", "transform_timeout", "predict_to_current_time", "print_diagnostics",
          "process_noise_covariance", "initial_estimate_covariance", "dynamic_process_noise_covariance",
          "gravitational_acceleration", "initial_state", "tf_prefix", "smooth_lagged_data", "history_length",
          *FRAME_PARAMETERS}


@dataclass
class Sensor:
    """One odomN/poseN/twistN/imuN input: its topic and the streams it feeds the filter."""
    name: str
    kind: str
    topic: str
    queue_size: int = 1
    nodelay: bool = False
    sources: dict = field(default_factory=dict)  # "pose", "twist", "acceleration" -> Source


@dataclass
class Config:
    frequency: float = 30.0
    sensor_timeout: float = 1.0 / 30.0
    two_d_mode: bool = False
    frames: Frames = field(default_factory=Frames)
    publish_tf: bool = True
    invert_tf: bool = False
    publish_acceleration: bool = False
    transform_time_offset: float = 0.0
    transform_timeout: float = 0.0
    predict_to_current_time: bool = False
    print_diagnostics: bool = True
    gravitational_acceleration: float = 9.80665
    process_noise_covariance: np.ndarray = field(default_factory=DEFAULT_PROCESS_NOISE.copy)
    initial_estimate_covariance: np.ndarray = None
    dynamic_process_noise_covariance: bool = False
    initial_state: np.ndarray = None
    history_length: float = None  # seconds of history kept with smooth_lagged_data, None without
    sensors: list = field(default_factory=list)


class Reader:
    """Reads one node's private parameters (a dict, as rospy.get_param('~') gives) and collects what is wrong as
    (level, line) pairs: 'error' for a bad value (the default is used), 'warn' for the rest."""

    def __init__(self, parameters):
        self.parameters = dict(parameters)
        self.problems = []
        self.read = set()

    def problem(self, level, line):
        self.problems.append((level, line))

    def get(self, name, default, check, expected, default_text=None):
        self.read.add(name)
        if name not in self.parameters:
            return default
        value = self.parameters[name]
        try:
            if check(value):
                return value
        except (TypeError, ValueError):
            pass
        self.problem("error", f"~{name}: {value!r} is not {expected}; {default_text or f'using {default!r}'}")
        return default

    def boolean(self, name, default):
        return self.get(name, default, lambda value: isinstance(value, bool), "true or false")

    def number(self, name, default, minimum=-math.inf, strict=False):
        value = self.get(name, default, lambda value: not isinstance(value, bool) and math.isfinite(value) and (
            value > minimum if strict else value >= minimum), f"a finite number {'>' if strict else '>='} {minimum}")
        return float(value)

    def text(self, name, default):
        return self.get(name, default, lambda value: isinstance(value, str) and value != "", "a non-empty string")

    def numbers(self, name, size):
        """A list of ``size`` finite numbers, or None."""
        return self.get(name, None, lambda value: isinstance(value, list) and len(value) == size and all(
            not isinstance(item, bool) and math.isfinite(item) for item in value), f"a list of {size} finite numbers",
            "using the default")

    def covariance(self, name):
        """A 15x15 covariance given as 225 numbers. As upstream (which reads them through a string stream),
        numbers YAML leaves as strings, such as 1e-9, are read as numbers."""
        size = STATE_SIZE * STATE_SIZE
        values = self.get(name, None, lambda value: isinstance(value, list) and len(value) == size and all(
            not isinstance(item, bool) and math.isfinite(float(item)) for item in value),
            f"a list of {size} finite numbers", "using the default")
        if values is None:
            return None
        matrix = np.array([float(value) for value in values]).reshape(STATE_SIZE, STATE_SIZE)
        if (np.diag(matrix) < 0).any() or not np.allclose(matrix, matrix.T):
            self.problem("error", f"~{name}: not a covariance (negative variance or not symmetric); using the default")
            return None
        return matrix


def read_config(parameters):
    """The Config of a parameter dict, and the problems found as (level, line) pairs."""
    reader = Reader(parameters)
    config = Config()
    config.frequency = reader.number("frequency", 30.0, minimum=0.0, strict=True)
    config.sensor_timeout = reader.number("sensor_timeout", 1.0 / config.frequency, minimum=0.0)
    config.two_d_mode = reader.boolean("two_d_mode", False)
    frames = config.frames
    frames.map = reader.text("map_frame", "map")
    frames.odom = reader.text("odom_frame", "odom")
    frames.base_link = reader.text("base_link_frame", "base_link")
    frames.base_link_output = reader.text("base_link_frame_output", frames.base_link)
    frames.world = reader.text("world_frame", frames.odom)
    prefix = reader.get("tf_prefix", "", lambda value: isinstance(value, str), "a string").strip("/")
    for attribute in ("map", "odom", "base_link", "base_link_output", "world"):
        frame = getattr(frames, attribute).lstrip("/")
        setattr(frames, attribute, f"{prefix}/{frame}" if prefix else frame)
    if len({frames.map, frames.odom, frames.base_link}) < 3 or frames.base_link_output in (frames.map, frames.odom):
        reader.problem("error", "~map_frame, ~odom_frame and ~base_link_frame must be unique (and "
                       "~base_link_frame_output differ from the first two)")
    if frames.world not in (frames.map, frames.odom):
        reader.problem("error", f"~world_frame: {frames.world!r} is neither map_frame nor odom_frame; using "
                       f"{frames.odom!r}")
        frames.world = frames.odom
    config.publish_tf = reader.boolean("publish_tf", True)
    config.invert_tf = reader.boolean("invert_tf", False)
    config.publish_acceleration = reader.boolean("publish_acceleration", False)
    config.transform_time_offset = reader.number("transform_time_offset", 0.0)
    config.transform_timeout = reader.number("transform_timeout", 0.0, minimum=0.0)
    config.predict_to_current_time = reader.boolean("predict_to_current_time", False)
    smooth_lagged_data = reader.boolean("smooth_lagged_data", False)
    given = reader.number("history_length", 0.0)
    if smooth_lagged_data:
        # Upstream uses the absolute value, saying so only below -1e9 (its test reads -1e9 for -1e-9).
        config.history_length = abs(given)
        if given < 0:
            reader.problem("warn", f"~history_length: {given} specified, negative; its absolute value "
                           f"{config.history_length} s is used")
    elif abs(given) > 1e-9:
        reader.problem("warn", f"~history_length: {given} specified, but smooth_lagged_data is false. "
                       "Lagged data will not be smoothed.")
    config.print_diagnostics = reader.boolean("print_diagnostics", True)
    config.gravitational_acceleration = reader.number("gravitational_acceleration", 9.80665)
    config.dynamic_process_noise_covariance = reader.boolean("dynamic_process_noise_covariance", False)
    noise = reader.covariance("process_noise_covariance")
    if noise is not None:
        config.process_noise_covariance = noise
    config.initial_estimate_covariance = reader.covariance("initial_estimate_covariance")
    initial_state = reader.numbers("initial_state", STATE_SIZE)
    config.initial_state = None if initial_state is None else np.array(initial_state, dtype=float)
    for kind in SENSOR_KINDS:
        index = 0
        while f"{kind}{index}" in reader.parameters:
            sensor = read_sensor(reader, kind, f"{kind}{index}")
            if sensor is not None:
                config.sensors.append(sensor)
            index += 1
    for name in UNSUPPORTED & set(reader.parameters):
        reader.problem("warn", f"~{name}: not supported by this ekf_localization_node, ignored")
    for name in sorted(set(reader.parameters) - reader.read - UNSUPPORTED):
        reader.problem("warn", unknown_line(name, reader.parameters))
    if config.print_diagnostics:
        coverage_problems(reader, config)
    return config, reader.problems


def unknown_line(name, parameters):
    match = SENSOR_NAME.match(name)
    if match:
        kind, index, setting = match.group(1), int(match.group(2)), match.group(3)
        missing = next((i for i in range(index + 1) if f"{kind}{i}" not in parameters), None)
        if missing is not None:
            return f"~{name}: not read, {kind}{missing} is missing (sensors are numbered from 0 without gaps)"
        if setting in UNSUPPORTED_SENSOR_SETTINGS:
            return f"~{name}: not supported by this ekf_localization_node, ignored"
        return f"~{name}: unknown setting for a {kind} input (known: {', '.join(sorted(SENSOR_SETTINGS[kind]))})"
    return f"~{name}: unknown parameter, ignored"


def read_update_config(reader, name):
    """The 15 booleans of ``name``_config, or None if they cannot be read."""
    parameter = f"{name}_config"
    reader.read.add(parameter)
    values = reader.parameters.get(parameter)
    if not isinstance(values, list) or not all(isinstance(value, (bool, int)) and not isinstance(value, float)
                                               for value in values):
        reader.problem("error", f"~{parameter}: {values!r} is not a list of {STATE_SIZE} booleans; {name} is not "
                       "used")
        return None
    if len(values) != STATE_SIZE:
        reader.problem("warn", f"~{parameter}: should have {STATE_SIZE} entries, has {len(values)}")
    update = np.zeros(STATE_SIZE, dtype=bool)
    count = min(len(values), STATE_SIZE)
    update[:count] = [bool(value) for value in values[:count]]
    return update


def read_sensor(reader, kind, name):
    settings = SENSOR_SETTINGS[kind]
    topic = reader.text(name, None)
    update = read_update_config(reader, name)
    if topic is None or update is None:
        return None

    def setting(suffix, read, *args):
        return read(f"{name}_{suffix}", *args) if suffix in settings else args[0]

    differential = setting("differential", reader.boolean, False)
    relative = setting("relative", reader.boolean, False)
    if differential and relative:
        reader.problem("warn", f"Both ~{name}_differential and ~{name}_relative were set to true. Using "
                       "differential mode.")
        relative = False
    queue_size = int(reader.get(f"{name}_queue_size", 1, lambda value: isinstance(value, int) and
                                not isinstance(value, bool) and value >= 1, "an integer >= 1"))
    nodelay = reader.boolean(f"{name}_nodelay", False)
    inf = math.inf
    pose_update, twist_update, acceleration_update = (update.copy() for _ in range(3))
    pose_update[VX:] = False
    # As upstream, an odometry or twist input's twist stream keeps the acceleration flags.
    twist_update[:VX] = False
    acceleration_update[:AX] = False
    sensor = Sensor(name, kind, topic, queue_size, nodelay)
    if kind == "imu":
        if update[X:X + 3].any():
            reader.problem("warn", f"~{name}_config: position entries are true, but sensor_msgs/Imu has no position")
        if update[VX:VX + 3].any():
            reader.problem("warn", f"~{name}_config: linear velocity entries are true, but sensor_msgs/Imu has "
                           "no linear velocity")
        pose_update[:3] = False
        twist_update[VX:VX + 3] = False
        twist_update[AX:] = False
        gravity = setting("remove_gravitational_acceleration", reader.boolean, False)
        sensor.sources = {
            "pose": Source(f"{name}_pose", pose_update, differential, relative,
                           setting("pose_rejection_threshold", reader.number, inf, 0.0)),
            "twist": Source(f"{name}_twist", twist_update, differential, relative,
                            setting("twist_rejection_threshold", reader.number, inf, 0.0)),
            "acceleration": Source(f"{name}_acceleration", acceleration_update, differential, relative,
                                   setting("linear_acceleration_rejection_threshold", reader.number, inf, 0.0),
                                   gravity)}
    elif kind == "odom":
        sensor.sources = {
            "pose": Source(f"{name}_pose", pose_update, differential, relative,
                           setting("pose_rejection_threshold", reader.number, inf, 0.0)),
            "twist": Source(f"{name}_twist", twist_update, False, False,
                            setting("twist_rejection_threshold", reader.number, inf, 0.0))}
    elif kind == "pose":
        sensor.sources = {"pose": Source(name, pose_update, differential, relative,
                                         setting("rejection_threshold", reader.number, inf, 0.0))}
    else:
        sensor.sources = {"twist": Source(name, twist_update, False, False,
                                          setting("rejection_threshold", reader.number, inf, 0.0))}
    if not any(source.update.any() for source in sensor.sources.values()):
        reader.problem("warn", f"~{name}: {topic} is listed as an input topic, but all its update variables are "
                       "false")
    return sensor


def coverage_problems(reader, config):
    """Upstream's configuration diagnostics: several absolute sources for one pose variable, or a pose variable
    measured neither absolutely nor through its velocity."""
    absolute, velocity = np.zeros(6, dtype=int), np.zeros(6, dtype=int)
    for sensor in config.sensors:
        pose = sensor.sources.get("pose")
        if pose is not None:
            (velocity if pose.differential else absolute)[:] += pose.update[:6]
        twist = sensor.sources.get("twist")
        if twist is not None:
            velocity[:] += twist.update[VX:VYAW + 1]
    planar = {0, 1, 5}
    for index in range(6):
        name = STATE_NAMES[index]
        if absolute[index] > 1:
            reader.problem("warn", f"{absolute[index]} absolute pose inputs detected for {name}. This may result "
                           "in oscillations. Please ensure that your variances for each measured variable are set "
                           "appropriately.")
        elif absolute[index] == 0 and velocity[index] == 0 and (index in planar or not config.two_d_mode):
            reader.problem("warn", f"Neither {name} nor its velocity is being measured. This will result in "
                           "unbounded error growth and erratic filter behavior.")
