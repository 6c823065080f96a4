"""What hector_gazebo_plugins' plugins share (IMU, GPS, magnetometer, sonar): their update timer
(``update_timer.h``), the time since the last update, the drifts redrawn on reset, the measured body, and the
warning for world spherical coordinates."""
from typing import Optional, Tuple

from ..clock import UpdateTimer
from ..errors import ConfigError
from ..log import get_logger, warn_once
from ..params import period
from ..sensors.body_sensors import gazebo_body
from .hector_sensor_model import SensorModel

_logger = get_logger(__name__)

HECTOR_UPDATE_PARAMS = (
    period("updatePeriod", 0.0, "s between updates; overrides updateRate when given", warn_if_missing=False),
)


def update_timer(params, now: float) -> UpdateTimer:
    """hector's UpdateTimer: ``updatePeriod`` wins over ``updateRate``; 0 = every physics step."""
    timer = UpdateTimer(params["updateRate"], start=now)
    if params["updatePeriod"]:
        timer.period = params["updatePeriod"]
    return timer


class HectorUpdates:
    """What hector's plugins share, mixed in before the Plugin class: ``elapsed`` gives the sim time since the
    last update (0 on the first after load or reset, as ``getTimeSinceLastUpdate``), and a reset redraws the
    drifts of the plugin's ``sensor_models``."""
    sensor_models: Tuple[SensorModel, ...] = ()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.last_update: Optional[float] = None

    def elapsed(self, now: float) -> float:
        dt = now - self.last_update if self.last_update is not None else 0.0
        self.last_update = now
        return dt

    def reset(self, now: float):
        super().reset(now)
        self.last_update = None
        for model in self.sensor_models:
            model.reset()


def warn_world_coordinates(params, where: str, what: str):
    """``useWorldSphericalCoordinates`` true: the world's <spherical_coordinates> are not read here."""
    if params["useWorldSphericalCoordinates"]:
        warn_once(_logger, f"{where}: <useWorldSphericalCoordinates> true is not emulated (the world's "
                           f"<spherical_coordinates> are not read); {what} apply")


def body_link(context, element, label: str, body: Optional[str]) -> str:
    """The link a hector plugin measures: ``bodyName`` (a lumped one becomes the link that survives, as
    sdformat renames it), else the model's root link as ``Model::GetLink()`` gives it."""
    robot = context.robot
    if body is None:
        return robot.model.root
    if body not in robot.model.lumped_into:
        raise ConfigError(f"{context.where(element)}: {label}: bodyName: {body} does not exist (links: "
                          f"{', '.join(sorted(robot.model.lumped_into))})")
    return gazebo_body(robot, body)[0]
