"""Names as gazebo_ros's plugins make them, in one place: each plugin's ``<robotNamespace>`` default, tf frame
resolution and the ``tf_prefix`` lookup.

Upstream's plugins differ in how an absent or empty ``<robotNamespace>`` resolves, and users' launch files
depend on those differences, so each plugin class names its rule (``Plugin.NAMESPACE_RULE``):

========== ============================= ====================== ==============================================
rule       absent                        empty                  plugins
========== ============================= ====================== ==============================================
MODEL      the model name                the model name         diff_drive, joint_state_publisher, ros_control,
                                                                tricycle_drive
SENSOR     the simulator's ("/")         the model name         laser, camera, multicamera, openni_kinect
ROOT       "/"                           "/"                    imu (the model plugin), p3d, f3d, ft_sensor,
                                                                planar_move, skid_steer, range, bumper, hector
                                                                imu, gps, magnetic and sonar, velodyne, block_laser,
                                                                roboticsgroup mimic_joint
IMU_SENSOR "/" + the model name          "/"                    imu_sensor
========== ============================= ====================== ==============================================
"""
from typing import Optional

from .parameters import Parameters

MODEL, SENSOR, ROOT, IMU_SENSOR = "model", "sensor", "root", "imu sensor"


def plugin_namespace(rule: str, tag: Optional[str], model_name: str) -> str:
    """The namespace of a plugin following ``rule``, from its ``<robotNamespace>`` text (None: absent)."""
    if rule == MODEL:
        return tag or model_name
    if rule == SENSOR:
        return "/" if tag is None else (tag or model_name)
    if rule == ROOT:
        return tag or "/"
    if rule == IMU_SENSOR:
        return "/" + model_name if tag is None else (tag or "/")
    raise ValueError(f"unknown namespace rule {rule!r}")


def resolve_frame(frame: str, prefix: str = "") -> str:
    """tf::resolve: an absolute frame loses its '/' and keeps no prefix; a relative one gets "prefix/"."""
    if frame.startswith("/"):
        return frame.lstrip("/")
    prefix = prefix.strip("/")
    return f"{prefix}/{frame}" if prefix else frame


def tf_prefix(parameters: Parameters, namespace: Optional[str]) -> str:
    """tf::getPrefixParam as a NodeHandle in ``namespace`` does it: the nearest ``tf_prefix`` parameter searched
    upwards from the namespace (how multi-robot launch files keep robots' frames apart), or ""."""
    name = parameters.search(namespace or "/", "tf_prefix")
    return str(parameters.get(name)) if name else ""
