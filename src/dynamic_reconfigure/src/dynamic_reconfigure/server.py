"""A dynamic_reconfigure server for a flat list of parameters, with upstream's interface on the wire.

As upstream's Python server: ``<ns>/set_parameters`` (Reconfigure) takes the parameters to change; values
beyond a parameter's bounds are clamped to them; the callback gets the whole new configuration and the level
(the OR of the changed parameters' levels; ~0 for the first call) and returns the configuration in effect, which
is answered, written to the parameter server under ``<ns>/`` and published latched on
``<ns>/parameter_updates``; ``<ns>/parameter_descriptions`` (latched) describes them all in one group,
"Default". At start, values on the parameter server override the initial ones.

Beyond upstream: a value of the wrong type or a name the server does not have is left out of the change and
said once in the log (upstream's Python server adds unknown names to its configuration).
"""
import math
import threading
from typing import Callable, Dict, List, NamedTuple, Union

import rospy
from dynamic_reconfigure.msg import (BoolParameter, Config, ConfigDescription, DoubleParameter, Group, GroupState,
                                     IntParameter, ParamDescription, StrParameter)
from dynamic_reconfigure.srv import Reconfigure, ReconfigureResponse

Value = Union[bool, int, float, str]
# Config's lists by parameter type, with their element messages.
_FIELDS = {"bool": ("bools", BoolParameter), "int": ("ints", IntParameter), "str": ("strs", StrParameter),
           "double": ("doubles", DoubleParameter)}
_TYPES = {"bool": bool, "int": int, "str": str, "double": float}
ALL_LEVELS = 0xFFFFFFFF  # the first call's level, upstream's ~0


class Parameter(NamedTuple):
    name: str
    type: str  # "double", "int", "bool" or "str"
    default: Value
    minimum: Value  # ignored for bool and str
    maximum: Value
    description: str
    level: int = 0


def encode(parameters: List[Parameter], values: Dict[str, Value]) -> Config:
    """A Config message holding ``values`` (of ``parameters``), in the group "Default"."""
    config = Config(groups=[GroupState(name="Default", state=True, id=0, parent=0)])
    for parameter in parameters:
        field, message_type = _FIELDS[parameter.type]
        getattr(config, field).append(message_type(name=parameter.name, value=values[parameter.name]))
    return config


def describe(parameters: List[Parameter]) -> ConfigDescription:
    group = Group(name="Default", type="", parent=0, id=0, parameters=[
        ParamDescription(name=parameter.name, type=parameter.type, level=parameter.level,
                         description=parameter.description, edit_method="") for parameter in parameters])
    return ConfigDescription(groups=[group], max=encode(parameters, {p.name: p.maximum for p in parameters}),
                             min=encode(parameters, {p.name: p.minimum for p in parameters}),
                             dflt=encode(parameters, {p.name: p.default for p in parameters}))


class Server:
    def __init__(self, parameters: List[Parameter], callback: Callable[[Dict[str, Value], int], Dict[str, Value]],
                 namespace: str = "~"):
        self.parameters = {parameter.name: parameter for parameter in parameters}
        self.callback = callback
        self.namespace = "~" if namespace == "~" else namespace.rstrip("/") + "/"
        self._lock = threading.Lock()
        self._warned = set()
        values = {parameter.name: parameter.default for parameter in parameters}
        for name in values:
            if rospy.has_param(self.namespace + name):
                values.update(self._checked({name: rospy.get_param(self.namespace + name)}))
        self._descriptions = rospy.Publisher(self.namespace + "parameter_descriptions", ConfigDescription,
                                             latch=True, queue_size=1)
        self._descriptions.publish(describe(parameters))
        self._updates = rospy.Publisher(self.namespace + "parameter_updates", Config, latch=True, queue_size=1)
        self.config: Dict[str, Value] = {}
        self._change(self._clamped(values), ALL_LEVELS)
        self._service = rospy.Service(self.namespace + "set_parameters", Reconfigure, self._set_parameters)

    def update_configuration(self, changes: Dict[str, Value]) -> Dict[str, Value]:
        """Change some parameters from inside the node, as a set_parameters call would."""
        with self._lock:
            wanted = self._clamped({**self.config, **self._checked(changes)})
            level = 0
            for name, value in wanted.items():
                if value != self.config[name]:
                    level |= self.parameters[name].level
            return self._change(wanted, level)

    def _set_parameters(self, request) -> ReconfigureResponse:
        sent = request.config
        changes = {item.name: item.value for item in sent.bools + sent.ints + sent.strs + sent.doubles}
        return ReconfigureResponse(config=encode(list(self.parameters.values()), self.update_configuration(changes)))

    def _change(self, values: Dict[str, Value], level: int) -> Dict[str, Value]:
        self.config = dict(self.callback(dict(values), level))
        for name, value in self.config.items():
            rospy.set_param(self.namespace + name, value)
        self._updates.publish(encode(list(self.parameters.values()), self.config))
        return self.config

    def _checked(self, changes: Dict[str, Value]) -> Dict[str, Value]:
        """The changes naming a parameter with a value of its type (an int for a double is taken)."""
        kept = {}
        for name, value in changes.items():
            parameter = self.parameters.get(name)
            wanted = _TYPES[parameter.type] if parameter else None
            if wanted is float and type(value) is int:
                value = float(value)
            if parameter is None or type(value) is not wanted:
                problem = "no such parameter" if parameter is None else f"not a {parameter.type}: {value!r}"
                self._warn_once(f"dynamic_reconfigure {self.namespace}: '{name}': {problem}; left out")
                continue
            kept[name] = value
        return kept

    def _clamped(self, values: Dict[str, Value]) -> Dict[str, Value]:
        """Numbers beyond a parameter's bounds put on them, as upstream's; NaN passes (the callback judges)."""
        clamped = dict(values)
        for name, value in values.items():
            parameter = self.parameters[name]
            if parameter.type in ("int", "double") and not (isinstance(value, float) and math.isnan(value)):
                clamped[name] = min(max(value, parameter.minimum), parameter.maximum)
        return clamped

    def _warn_once(self, message: str):
        if message not in self._warned:
            self._warned.add(message)
            rospy.logwarn(message)
