"""Plugin and sensor tags read the way gazebo_ros's ``GazeboRos::getParameter`` reads them.

Each plugin declares its tags once, as a tuple of ``Param``; defaults, valid ranges, warnings, docs and tests
all come from that table. A missing tag warns with its default (as Gazebo does); a bad or out-of-range value
raises ``ConfigError`` naming where it is, the plugin, the tag, the value and the valid range; an unknown tag
warns once and lists the known ones. Gazebo accepts out-of-range numbers and then divides by zero or flies
the robot off; the bridge refuses the spawn instead.
"""
from dataclasses import dataclass
from typing import Any, Callable, Dict, Optional, Sequence, Tuple
from xml.etree import ElementTree

from .errors import ConfigError
from .log import get_logger, info_once, warn_once
from .xml_values import check_range, describe_range, parse_bool, parse_float, parse_int

_logger = get_logger(__name__)

# The largest error model value (noise, drift, offset, scale) a sensor tag may give: far beyond any sensor, and
# small enough that the products a sensor model forms stay finite.
ERROR_MODEL_LIMIT = 1e6
# The slowest update rate (Hz) and longest update period (s) a tag may give: one update in 11.6 days of sim
# time. A rate of 1e-308 Hz is a period of 1e308 s, which overflows when counted in physics steps.
MIN_RATE = 1e-6
MAX_PERIOD = 1.0 / MIN_RATE

_PARSERS: Dict[type, Callable[[str], Any]] = {bool: parse_bool, float: parse_float, int: parse_int, str: str.strip}


@dataclass(frozen=True)
class Param:
    tag: str  # a child of the element read, or a path below it ("ray/range/min")
    kind: type
    default: Any = None
    doc: str = ""
    required: bool = False
    choices: Optional[Tuple[str, ...]] = None
    # False for tags Gazebo reads without a warning when absent (e.g. the diff drive's publishOdomTF).
    warn_if_missing: bool = True
    minimum: Optional[float] = None
    maximum: Optional[float] = None
    exclusive_minimum: bool = False  # True: value > minimum
    least_positive: Optional[float] = None  # values in (0, least_positive) are refused too

    @property
    def valid_range(self) -> str:
        if self.choices is not None:
            return "one of " + ", ".join(self.choices)
        if self.kind in (int, float):
            return describe_range(self.minimum, self.maximum, self.exclusive_minimum, self.least_positive)
        return ""


def positive(tag: str, kind: type, default: Any, doc: str = "", **options) -> Param:
    """A number that must be > 0 (a length, a rate that cannot be zero)."""
    return Param(tag, kind, default, doc, minimum=0, exclusive_minimum=True, **options)


def non_negative(tag: str, kind: type, default: Any, doc: str = "", **options) -> Param:
    return Param(tag, kind, default, doc, minimum=0, **options)


def rate(tag: str, default: float, doc: str = "", signed: bool = False, **options) -> Param:
    """An update rate in Hz: 0 (or any value <= 0 when ``signed``) has the tag's own meaning, usually every
    physics step; a positive rate is at least MIN_RATE."""
    if not signed:
        options.setdefault("minimum", 0)
    return Param(tag, float, default, doc, least_positive=MIN_RATE, **options)


def period(tag: str, default: float, doc: str = "", **options) -> Param:
    """An update period in s, at most MAX_PERIOD."""
    return Param(tag, float, default, doc, minimum=0, maximum=MAX_PERIOD, **options)


class PluginParams:
    """Reads one ``<plugin>`` (or ``<sensor>``) element against a Param table.

    ``label`` names the plugin in every message ("GazeboRosDiffDrive(ns = /)"); ``where`` locates the
    element ("model 'mbot':57"). ``check_unknown`` warns about children no Param names (plugins; a
    sensor's SDF has many tags read elsewhere or by Gazebo's rendering, so sensors skip it).
    """

    def __init__(self, element: ElementTree.Element, label: str, ignored: Sequence[str] = (), where: str = "",
                 check_unknown: bool = True):
        self._element = element
        self.label = label
        self._prefix = f"{where}: {label}" if where else label
        self._ignored = tuple(ignored)
        self._check_unknown = check_unknown

    def read(self, params: Sequence[Param]) -> Dict[str, Any]:
        values = {param.tag: self._read_one(param) for param in params}
        if self._check_unknown:
            known = {param.tag for param in params} | set(self._ignored)
            for child in self._element:
                if child.tag in self._ignored:
                    info_once(_logger, f"{self.label}: <{child.tag}> is accepted and has no effect, "
                                       f"as in gazebo_ros")
                elif child.tag not in known:
                    warn_once(_logger, f"{self.label}: unknown tag <{child.tag}> ignored; known tags: "
                                       f"{', '.join(sorted(known))}")
        return values

    def _read_one(self, param: Param) -> Any:
        child = self._element.find(param.tag)
        if child is None or child.text is None or not child.text.strip():
            if param.required:
                raise ConfigError(f"{self._prefix}: missing required tag <{param.tag}>")
            if param.warn_if_missing:
                warn_once(_logger, f"{self.label}: missing <{param.tag}>, default is {param.default}")
            return param.default
        text = child.text.strip()
        try:
            value = _PARSERS[param.kind](text)
            if param.kind in (int, float):
                check_range(value, param.minimum, param.maximum, param.exclusive_minimum, param.least_positive)
        except ValueError as error:
            raise ConfigError(f"{self._prefix}: <{param.tag}> has bad value '{text}': {error}") from None
        if param.choices is not None and value not in param.choices:
            raise ConfigError(f"{self._prefix}: <{param.tag}> is '{value}'; expected one of "
                              f"{', '.join(param.choices)}")
        _logger.debug(f"{self.label}: <{param.tag}> = {value}")
        return value


def params_table_markdown(params: Sequence[Param]) -> str:
    """The README table of a plugin's tags, generated from the same data the plugin reads."""
    rows = ["| Tag | Type | Default | Valid | Meaning |", "|-----|------|---------|-------|---------|"]
    for param in params:
        default = "(required)" if param.required else repr(param.default)
        rows.append(f"| `{param.tag}` | {param.kind.__name__} | {default} | {param.valid_range} | {param.doc} |")
    return "\n".join(rows)
