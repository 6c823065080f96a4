"""Gazebo plugin file name -> the ROS class that emulates it, derived from the one plugin table
(``core/plugin_table.py``) and, like it, loaded at a file name's first lookup.

A plugin's ROS class is in the module of this package named after the first file name of its core class in the
table (``libgazebo_ros_laser.so`` and ``libgazebo_ros_gpu_laser.so``: ``gazebo_ros_laser.py``). It is that
module's class whose nearest core ancestor is the table's core class (the ROS side of ``DepthCamera`` is
``GazeboRosOpenniKinect``; of ``PlainDepthCamera``, ``GazeboRosDepthCamera``, which extends both). So adding a
plugin needs no line here.
"""
import importlib
from typing import Mapping

from ..core.plugin import Plugin
from ..core.plugin_table import CORE_PLUGINS, LazyClassTable, filename_of

_PACKAGE = __name__.rsplit(".", 1)[0]
_CORE_PACKAGE = Plugin.__module__.rsplit(".", 1)[0]


def _nearest_core_class(ros_class: type) -> type:
    return next(base for base in ros_class.__mro__[1:] if base.__module__.startswith(_CORE_PACKAGE + "."))


def home_module(filename: str) -> str:
    """The name of the module of this package that holds ``filename``'s ROS class."""
    first = filename_of(CORE_PLUGINS[filename])
    return f"{_PACKAGE}.{first[len('lib'):-len('.so')]}"


def plugin_classes(module) -> list:
    """The plugin classes ``module`` defines (not those it imports)."""
    return [value for value in vars(module).values()
            if isinstance(value, type) and issubclass(value, Plugin) and value.__module__ == module.__name__]


def find_ros_class(filename: str) -> type:
    """``filename``'s ROS class, from its home module (REGISTRY keeps what this finds)."""
    core_class = CORE_PLUGINS[filename]
    module_name = home_module(filename)
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as error:
        if error.name != module_name:
            raise
        raise ImportError(f"{filename}: the ROS side of {core_class.__name__} belongs in {module_name}, which is "
                          "missing") from None
    candidates = [ros_class for ros_class in plugin_classes(module) if _nearest_core_class(ros_class) is core_class]
    if len(candidates) != 1:
        found = ", ".join(candidate.__name__ for candidate in candidates) or "none"
        raise ImportError(f"{filename}: {module_name} must have one class extending {core_class.__name__} first; "
                          f"found {found}")
    return candidates[0]


REGISTRY: Mapping[str, type] = LazyClassTable(CORE_PLUGINS, find_ros_class)
