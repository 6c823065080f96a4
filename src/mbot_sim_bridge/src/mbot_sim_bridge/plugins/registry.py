"""Gazebo plugin file name -> the class that emulates it. Adding a plugin adds one line here."""
from .gazebo_ros_camera import GazeboRosCamera
from .gazebo_ros_control import GazeboRosControl
from .gazebo_ros_diff_drive import GazeboRosDiffDrive
from .gazebo_ros_joint_state_publisher import GazeboRosJointStatePublisher
from .gazebo_ros_imu import GazeboRosImu
from .gazebo_ros_imu_sensor import GazeboRosImuSensor
from .gazebo_ros_laser import GazeboRosLaser
from .gazebo_ros_openni_kinect import GazeboRosDepthCamera, GazeboRosOpenniKinect
from .gazebo_ros_p3d import GazeboRosP3D

REGISTRY = {
    "libgazebo_ros_control.so": GazeboRosControl,
    "libgazebo_ros_diff_drive.so": GazeboRosDiffDrive,
    "libgazebo_ros_joint_state_publisher.so": GazeboRosJointStatePublisher,
    "libgazebo_ros_laser.so": GazeboRosLaser,
    "libgazebo_ros_gpu_laser.so": GazeboRosLaser,
    "libgazebo_ros_camera.so": GazeboRosCamera,
    "libgazebo_ros_openni_kinect.so": GazeboRosOpenniKinect,
    "libgazebo_ros_depth_camera.so": GazeboRosDepthCamera,
    "libgazebo_ros_imu.so": GazeboRosImu,
    "libgazebo_ros_imu_sensor.so": GazeboRosImuSensor,
    "libgazebo_ros_p3d.so": GazeboRosP3D,
}
