"""Gazebo plugin file name -> the ROS class that emulates it, derived from the one plugin table
(``core/plugin_table.py``).

A plugin's ROS class is the class of this package whose nearest core ancestor is the table's core class (the
ROS side of ``DepthCamera`` is ``GazeboRosOpenniKinect``; of ``PlainDepthCamera``, ``GazeboRosDepthCamera``,
which extends both). Every module of this package is imported to find them, so adding a plugin needs no line
here.
"""
import importlib
import pkgutil

from ..core.plugin import Plugin
from ..core.plugin_table import CORE_PLUGINS

_PACKAGE = __name__.rsplit(".", 1)[0]
_CORE_PACKAGE = Plugin.__module__.rsplit(".", 1)[0]


def _ros_classes():
    classes = []
    for module_info in pkgutil.iter_modules(importlib.import_module(_PACKAGE).__path__):
        module = importlib.import_module(f"{_PACKAGE}.{module_info.name}")
        classes += [value for value in vars(module).values()
                    if isinstance(value, type) and issubclass(value, Plugin) and value.__module__ == module.__name__]
    return classes


def _nearest_core_class(ros_class: type) -> type:
    return next(base for base in ros_class.__mro__[1:] if base.__module__.startswith(_CORE_PACKAGE + "."))


def _derive():
    faces = {}
    for ros_class in _ros_classes():
        faces.setdefault(_nearest_core_class(ros_class), []).append(ros_class)
    registry = {}
    for filename, core_class in CORE_PLUGINS.items():
        candidates = faces.get(core_class, [])
        if len(candidates) != 1:
            found = ", ".join(candidate.__name__ for candidate in candidates) or "none"
            raise ImportError(f"{filename}: {_PACKAGE} must have one class extending {core_class.__name__} first; "
                              f"found {found}")
        registry[filename] = candidates[0]
    return registry


REGISTRY = _derive()
