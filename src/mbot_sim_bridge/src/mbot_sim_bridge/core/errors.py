"""Errors the bridge reports as one line and stops on (Gymnasium-style small tree)."""


class BridgeError(Exception):
    """Base of every error the bridge turns into a one-line fatal message."""


class ConfigError(BridgeError):
    """A <gazebo> block, plugin tag, launch argument or parameter is wrong."""


class PluginLeftOut(BridgeError):
    """A plugin that cannot run beside another (both would advertise one ROS name): left out with one warning
    naming both, and the model or world goes on without it."""


class ModelError(BridgeError):
    """A robot_description or model XML cannot be turned into a simulated model."""


class WorldError(BridgeError):
    """A .world file is missing, malformed or cannot be built."""
