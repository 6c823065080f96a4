"""Every emulated Gazebo plugin: the file name a ``<plugin filename=...>`` gives -> its core class (no ROS).

This is the one plugin table. The ROS node's registry (``plugins/registry.py``) is derived from it, and the demo,
the benchmarks and the tests build their Simulations from it; adding a plugin adds one line here.
"""
from typing import Dict

from .block_laser import BlockLaser
from .bumper import Bumper
from .camera import Camera, DepthCamera, PlainDepthCamera
from .diff_drive import DiffDrive
from .f3d import F3D
from .ft_sensor import FTSensor
from .gazebo_ros_control import GazeboRosControlPlugin
from .hector_gps import HectorGps
from .hector_imu import HectorImu
from .hector_magnetic import HectorMagnetic
from .imu import ImuModelPlugin, ImuSensor
from .joint_states import JointStatePublisher
from .lidar import RaySensor
from .mimic_joint import MIMIC_PLUGIN, MimicJoint
from .multicamera import MultiCamera
from .p3d import P3D
from .planar_move import PlanarMove
from .range_sensor import HectorSonar, RangeSensor
from .skid_steer_drive import SkidSteerDrive
from .tricycle_drive import TricycleDrive
from .velodyne_laser import VelodyneLaser

CORE_PLUGINS: Dict[str, type] = {
    "libgazebo_ros_control.so": GazeboRosControlPlugin,
    "libgazebo_ros_diff_drive.so": DiffDrive,
    "libgazebo_ros_joint_state_publisher.so": JointStatePublisher,
    "libgazebo_ros_laser.so": RaySensor,
    "libgazebo_ros_gpu_laser.so": RaySensor,
    "libgazebo_ros_camera.so": Camera,
    "libgazebo_ros_multicamera.so": MultiCamera,
    "libgazebo_ros_openni_kinect.so": DepthCamera,
    "libgazebo_ros_depth_camera.so": PlainDepthCamera,
    "libgazebo_ros_imu.so": ImuModelPlugin,
    "libgazebo_ros_imu_sensor.so": ImuSensor,
    "libgazebo_ros_p3d.so": P3D,
    "libgazebo_ros_f3d.so": F3D,
    "libgazebo_ros_ft_sensor.so": FTSensor,
    "libgazebo_ros_planar_move.so": PlanarMove,
    "libgazebo_ros_skid_steer_drive.so": SkidSteerDrive,
    "libgazebo_ros_tricycle_drive.so": TricycleDrive,
    "libhector_gazebo_ros_imu.so": HectorImu,
    "libhector_gazebo_ros_gps.so": HectorGps,
    "libhector_gazebo_ros_magnetic.so": HectorMagnetic,
    "libgazebo_ros_range.so": RangeSensor,
    "libgazebo_ros_bumper.so": Bumper,
    "libhector_gazebo_ros_sonar.so": HectorSonar,
    "libgazebo_ros_velodyne_laser.so": VelodyneLaser,
    "libgazebo_ros_velodyne_gpu_laser.so": VelodyneLaser,
    "libgazebo_ros_block_laser.so": BlockLaser,
    MIMIC_PLUGIN: MimicJoint,
    # The same plugin under the package's name before 2020.
    "libroboticsgroup_gazebo_mimic_joint_plugin.so": MimicJoint,
}


def filename_of(plugin_class: type) -> str:
    """The (first) file name under which the core class ``plugin_class`` is in the table."""
    return next(filename for filename, core_class in CORE_PLUGINS.items() if core_class is plugin_class)
