"""hector_gazebo_plugins' sensor error model (``sensor_model.h``), shared by its IMU, GPS, magnetometer and sonar.

Per axis: ``measured = value · scaleError + offset + drift + n``, where n ~ N(0, gaussianNoise) is drawn on
every update and the drift is a first-order Gauss-Markov process,
``drift ← exp(−dt·driftFrequency)·drift + dt·N(0, sqrt(2·driftFrequency)·drift_stddev)``, started at
N(0, drift_stddev) on load and on every reset. The tags are ``<prefix>Offset``, ``<prefix>Drift``,
``<prefix>DriftFrequency``, ``<prefix>GaussianNoise`` and ``<prefix>ScaleError`` (no prefix: ``offset``,
``drift``, ...); hector reads them without warning when absent. A vector model takes three numbers per tag.
Draws come from the plugin's own random stream (hector uses ``rand()``), so reruns are identical.
"""
from typing import Dict, Sequence, Tuple

import numpy as np

from ..errors import ConfigError
from ..params import ERROR_MODEL_LIMIT as LIMIT, Param
from ..xml_values import parse_floats

# driftFrequency's default: a one-hour time constant.
_DRIFT_FREQUENCY = 1.0 / 3600.0

# (tag suffix, default, must be non-negative, meaning)
_FIELDS = (
    ("Offset", 0.0, False, "constant bias"),
    ("Drift", 0.0, True, "stddev of the drifting bias"),
    ("DriftFrequency", _DRIFT_FREQUENCY, True, "1/s; inverse time constant of the drift"),
    ("GaussianNoise", 0.0, True, "stddev of the white noise"),
    ("ScaleError", 1.0, False, "factor on the true value"),
)


def _tag(prefix: str, suffix: str) -> str:
    return prefix + suffix if prefix else suffix[0].lower() + suffix[1:]


def sensor_model_params(prefix: str, size: int, quantity: str) -> Tuple[Param, ...]:
    """The five tags of a model; vectors (size 3) are read as text and checked by ``SensorModel.from_params``."""
    params = []
    for suffix, default, non_negative, meaning in _FIELDS:
        if size == 1:
            params.append(Param(_tag(prefix, suffix), float, default, f"{quantity}: {meaning}",
                                warn_if_missing=False, minimum=0.0 if non_negative else -LIMIT, maximum=LIMIT))
        else:
            low = "0" if non_negative else f"-{LIMIT:g}"
            params.append(Param(_tag(prefix, suffix), str, " ".join([f"{default:g}"] * size),
                                f"{quantity}: {meaning}, per axis, each {low} to {LIMIT:g}", warn_if_missing=False))
    return tuple(params)


class SensorModel:
    """One hector SensorModel of ``size`` axes (1: the yaw model; 3: acceleration, rate, position, velocity)."""

    def __init__(self, offset, drift, drift_frequency, gaussian_noise, scale_error, rng: np.random.Generator):
        self.offset, self.drift, self.drift_frequency, self.gaussian_noise, self.scale_error = (
            np.asarray(value, dtype=float) for value in (offset, drift, drift_frequency, gaussian_noise, scale_error))
        self.rng = rng
        self.reset()

    @classmethod
    def from_params(cls, values: Dict[str, object], prefix: str, size: int, rng: np.random.Generator,
                    where: str) -> "SensorModel":
        """The model from a plugin's read params; a vector tag that is not ``size`` finite numbers, or a
        negative drift, frequency or noise, raises ConfigError naming the tag."""
        fields = []
        for suffix, _, non_negative, _ in _FIELDS:
            tag = _tag(prefix, suffix)
            value = values[tag]
            if size > 1:
                try:
                    value = parse_floats(value, size)
                except ValueError as error:
                    raise ConfigError(f"{where}: <{tag}> has bad value '{value}': {error}") from None
            if non_negative and np.any(np.asarray(value) < 0):
                raise ConfigError(f"{where}: <{tag}> has bad value '{values[tag]}': must be >= 0")
            if np.any(np.abs(np.asarray(value)) > LIMIT):
                raise ConfigError(f"{where}: <{tag}> has bad value '{values[tag]}': must be at most {LIMIT:g} in size")
            fields.append(value)
        return cls(*fields, rng)

    @property
    def bias(self) -> np.ndarray:
        """hector's getCurrentBias: drift plus offset."""
        return self.current_drift + self.offset

    def reset(self, drift: Sequence[float] = None):
        """A fresh drift drawn from N(0, drift), or the given one (the calibrate service sets it to zero)."""
        if drift is None:
            self.current_drift = self.rng.normal(0.0, 1.0, self.offset.shape) * self.drift
        else:
            self.current_drift = np.asarray(drift, dtype=float) * np.ones(self.offset.shape)
        self.current_error = np.zeros(self.offset.shape)

    def update(self, dt: float) -> np.ndarray:
        """Advance the drift by ``dt`` and draw the error of one measurement."""
        decay = np.exp(-dt * self.drift_frequency)
        step = np.sqrt(2.0 * self.drift_frequency) * self.drift
        self.current_drift = decay * self.current_drift + dt * self.rng.normal(0.0, 1.0, self.offset.shape) * step
        self.current_error = (self.offset + self.current_drift
                              + self.rng.normal(0.0, 1.0, self.offset.shape) * self.gaussian_noise)
        return self.current_error

    def __call__(self, value, dt: float) -> np.ndarray:
        return np.asarray(value, dtype=float) * self.scale_error + self.update(dt)
