"""Every emulated Gazebo plugin: the file name a ``<plugin filename=...>`` gives -> its core class (no ROS).

This is the one plugin table. The ROS node's registry (``plugins/registry.py``) is derived from it, and the demo,
the benchmarks and the tests build their Simulations from it; adding a plugin adds one line here.

A line names its class as ``module.Class`` relative to this package (``drives.diff_drive.DiffDrive``), imported
when a model first uses the file name, as Gazebo loads a plugin's library only when a model names it: a launch
imports the plugins its models use, not all of them (importing every plugin, with its ROS side, took 30 ms of the
simulator's start-up).
"""
import importlib
from typing import Callable, Dict, Iterable, Iterator, Mapping

_REFERENCES: Dict[str, str] = {
    "libgazebo_ros_control.so": "ros_control.gazebo_ros_control.GazeboRosControlPlugin",
    "libgazebo_ros_diff_drive.so": "drives.diff_drive.DiffDrive",
    "libgazebo_ros_joint_state_publisher.so": "joints.joint_states.JointStatePublisher",
    "libgazebo_ros_laser.so": "sensors.lidar.RaySensor",
    "libgazebo_ros_gpu_laser.so": "sensors.lidar.RaySensor",
    "libgazebo_ros_camera.so": "cameras.camera.Camera",
    "libgazebo_ros_multicamera.so": "cameras.multicamera.MultiCamera",
    "libgazebo_ros_openni_kinect.so": "cameras.camera.DepthCamera",
    "libgazebo_ros_depth_camera.so": "cameras.camera.PlainDepthCamera",
    "libgazebo_ros_imu.so": "sensors.imu.ImuModelPlugin",
    "libgazebo_ros_imu_sensor.so": "sensors.imu.ImuSensor",
    "libgazebo_ros_p3d.so": "sensors.p3d.P3D",
    "libgazebo_ros_f3d.so": "sensors.f3d.F3D",
    "libgazebo_ros_ft_sensor.so": "sensors.ft_sensor.FTSensor",
    "libgazebo_ros_planar_move.so": "drives.planar_move.PlanarMove",
    "libgazebo_ros_force.so": "manipulation.force.Force",
    "libgazebo_ros_vacuum_gripper.so": "manipulation.vacuum_gripper.VacuumGripper",
    "libgazebo_ros_link_attacher.so": "manipulation.link_attacher.LinkAttacher",
    "libgazebo_grasp_fix.so": "manipulation.grasp_fix.GraspFix",
    "libgazebo_ros_skid_steer_drive.so": "drives.skid_steer_drive.SkidSteerDrive",
    "libgazebo_ros_tricycle_drive.so": "drives.tricycle_drive.TricycleDrive",
    "libhector_gazebo_ros_imu.so": "hector.hector_imu.HectorImu",
    "libhector_gazebo_ros_gps.so": "hector.hector_gps.HectorGps",
    "libhector_gazebo_ros_magnetic.so": "hector.hector_magnetic.HectorMagnetic",
    "libgazebo_ros_range.so": "sensors.range_sensor.RangeSensor",
    "libgazebo_ros_bumper.so": "sensors.bumper.Bumper",
    "libhector_gazebo_ros_sonar.so": "sensors.range_sensor.HectorSonar",
    "libgazebo_ros_velodyne_laser.so": "sensors.velodyne_laser.VelodyneLaser",
    "libgazebo_ros_velodyne_gpu_laser.so": "sensors.velodyne_laser.VelodyneLaser",
    "libgazebo_ros_block_laser.so": "sensors.block_laser.BlockLaser",
    "libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so": "joints.mimic_joint.MimicJoint",
    # The same plugin under the package's name before 2020.
    "libroboticsgroup_gazebo_mimic_joint_plugin.so": "joints.mimic_joint.MimicJoint",
    # gazebo_plugins' template, which does nothing: the starting point of a new plugin.
    "libgazebo_ros_template.so": "template.Template",
}


class LazyClassTable(Mapping):
    """Key -> class, each made by ``load(key)`` at its first lookup and kept; an unknown key is a KeyError."""

    def __init__(self, keys: Iterable[str], load: Callable[[str], type]):
        self._keys = dict.fromkeys(keys)  # ordered, for iteration and membership
        self._load = load
        self._classes: Dict[str, type] = {}

    def __getitem__(self, key: str) -> type:
        loaded = self._classes.get(key)
        if loaded is None:
            if key not in self._keys:
                raise KeyError(key)
            loaded = self._classes[key] = self._load(key)
        return loaded

    def __iter__(self) -> Iterator[str]:
        return iter(self._keys)

    def __len__(self) -> int:
        return len(self._keys)


def _import(filename: str) -> type:
    module, name = _REFERENCES[filename].rsplit(".", 1)
    return getattr(importlib.import_module(f"{__package__}.{module}"), name)


CORE_PLUGINS: Mapping[str, type] = LazyClassTable(_REFERENCES, _import)


def filename_of(plugin_class: type) -> str:
    """The (first) file name under which the core class ``plugin_class`` is in the table; imports no other."""
    reference = f"{plugin_class.__module__[len(__package__) + 1:]}.{plugin_class.__name__}"
    return next(filename for filename, entry in _REFERENCES.items() if entry == reference)
