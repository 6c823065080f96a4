"""The model and resource paths as gazebo_ros's paths plugin builds them: the core's order (GAZEBO_* variables,
the exports, the workspace) with the folders that packages export to gazebo_ros in their package.xml
(``<export><gazebo_ros gazebo_model_path="${prefix}/models"/></export>``).

The exports are collected with ``rospack plugins``, the command the paths plugin runs through librospack: it
reads package.xml files on ROS_PACKAGE_PATH, needs no ROS master, and lists only packages that depend on
gazebo_ros directly, with ``${prefix}`` replaced by the package's folder.
"""
import subprocess
from typing import Dict, List

from .core.log import get_logger, warn_once
from .core.description.model_path import default_model_path, default_resource_path

# rospack answers from its cache in milliseconds; a first crawl of a large ROS_PACKAGE_PATH takes longer.
_ROSPACK_TIMEOUT_SECONDS = 60.0

_log = get_logger(__name__)
# attribute -> its rospack run, started by prefetch_package_exports
_prefetched: Dict[str, subprocess.Popen] = {}


def model_path() -> List[str]:
    """Where ``model://NAME`` is looked up."""
    return default_model_path(package_exports("gazebo_model_path"))


def resource_path() -> List[str]:
    """Where world files and ``file://`` URIs are looked up."""
    return default_resource_path(package_exports("gazebo_media_path"))


def prefetch_package_exports(attribute: str):
    """Start ``rospack plugins`` for ``attribute`` now, for the next ``package_exports(attribute)`` in this
    process to collect: the simulator starts it before its imports, which outlast it (rospack takes 40 to 70 ms
    here, on the way to the first /odom otherwise)."""
    try:
        _prefetched[attribute] = subprocess.Popen(_rospack_command(attribute), stdout=subprocess.PIPE,
                                                  stderr=subprocess.PIPE, text=True)
    except FileNotFoundError:
        pass  # package_exports runs it again and says so


def package_exports(attribute: str) -> List[str]:
    """The folders packages export to gazebo_ros under ``attribute`` (gazebo_model_path, gazebo_media_path,
    plugin_path), in rospack's order; each value may hold several folders separated by ':'."""
    command = _rospack_command(attribute)
    try:
        process = _prefetched.pop(attribute, None) or subprocess.Popen(
            command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    except FileNotFoundError:
        warn_once(_log, f"rospack is not installed (Debian package rospack-tools): the {attribute} that packages "
                        "export in package.xml are not searched")
        return []
    try:
        stdout, stderr = process.communicate(timeout=_ROSPACK_TIMEOUT_SECONDS)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        warn_once(_log, f"'{' '.join(command)}' took more than {_ROSPACK_TIMEOUT_SECONDS:.0f} s: the {attribute} "
                        "exports are not searched")
        return []
    if process.returncode != 0:
        # No gazebo_ros on ROS_PACKAGE_PATH (a plain pytest run, an unsourced shell): nothing can export to it.
        _log.debug(f"{' '.join(command)}: {stderr.strip()}")
        return []
    directories = []
    for line in stdout.splitlines():
        _package, _, value = line.strip().partition(" ")
        directories += [entry for entry in value.split(":") if entry.strip()]
    return directories


def _rospack_command(attribute: str) -> List[str]:
    return ["rospack", "plugins", "--attrib=" + attribute, "gazebo_ros"]
