"""Plugin tags read the way gazebo_ros's ``GazeboRos::getParameter`` reads them.

Each plugin declares its tags once, as a tuple of ``Param``; defaults, warnings, docs and tests all come from
that table. A missing tag warns with its default (as Gazebo does), a bad value raises ``ConfigError`` naming
the tag, the value and the plugin, and an unknown tag warns once and lists the known ones.
"""
import math
from dataclasses import dataclass
from typing import Any, Callable, Dict, Optional, Sequence, Tuple
from xml.etree import ElementTree

from .errors import ConfigError
from .log import get_logger, warn_once

_logger = get_logger(__name__)

_TRUE = ("true", "1")
_FALSE = ("false", "0")


def parse_bool(text: str) -> bool:
    """Gazebo accepts true/false/1/0 in any case."""
    value = text.strip().lower()
    if value in _TRUE:
        return True
    if value in _FALSE:
        return False
    raise ValueError("expected true, false, 1 or 0")


def parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError("expected a finite number")
    return value


_PARSERS: Dict[type, Callable[[str], Any]] = {bool: parse_bool, float: parse_float, int: int, str: str.strip}


@dataclass(frozen=True)
class Param:
    tag: str
    kind: type
    default: Any = None
    doc: str = ""
    required: bool = False
    choices: Optional[Tuple[str, ...]] = None
    # False for tags Gazebo reads without a warning when absent (e.g. the diff drive's publishOdomTF).
    warn_if_missing: bool = True


class PluginParams:
    """Reads one ``<plugin>`` element against a Param table. ``label`` names the plugin in every message."""

    def __init__(self, element: ElementTree.Element, label: str, ignored: Sequence[str] = ()):
        self._element = element
        self.label = label
        self._ignored = tuple(ignored)

    def read(self, params: Sequence[Param]) -> Dict[str, Any]:
        values = {param.tag: self._read_one(param) for param in params}
        known = {param.tag for param in params} | set(self._ignored)
        for child in self._element:
            if not isinstance(child.tag, str):
                continue  # an XML comment
            if child.tag in self._ignored:
                _logger.debug("%s: <%s> is accepted and has no effect, as in gazebo_ros", self.label, child.tag)
            elif child.tag not in known:
                warn_once(_logger, "%s: unknown tag <%s> ignored; known tags: %s"
                          % (self.label, child.tag, ", ".join(sorted(known))))
        return values

    def _read_one(self, param: Param) -> Any:
        child = self._element.find(param.tag)
        if child is None or child.text is None or not child.text.strip():
            if param.required:
                raise ConfigError("%s: missing required tag <%s>" % (self.label, param.tag))
            if param.warn_if_missing:
                warn_once(_logger, "%s: missing <%s>, default is %s" % (self.label, param.tag, param.default))
            return param.default
        text = child.text.strip()
        try:
            value = _PARSERS[param.kind](text)
        except ValueError as error:
            raise ConfigError("%s: <%s> has bad value '%s': %s" % (self.label, param.tag, text, error)) from None
        if param.choices is not None and value not in param.choices:
            raise ConfigError("%s: <%s> is '%s'; expected one of %s"
                              % (self.label, param.tag, value, ", ".join(param.choices)))
        _logger.debug("%s: <%s> = %s", self.label, param.tag, value)
        return value


def params_table_markdown(params: Sequence[Param]) -> str:
    """The README table of a plugin's tags, generated from the same data the plugin reads."""
    rows = ["| Tag | Type | Default | Meaning |", "|-----|------|---------|---------|"]
    for param in params:
        default = "(required)" if param.required else repr(param.default)
        rows.append("| `%s` | %s | %s | %s |" % (param.tag, param.kind.__name__, default, param.doc))
    return "\n".join(rows)
