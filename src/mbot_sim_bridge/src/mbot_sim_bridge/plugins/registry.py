"""Gazebo plugin file name -> the class that emulates it. Adding a plugin adds one line here."""
from .gazebo_ros_diff_drive import GazeboRosDiffDrive
from .gazebo_ros_joint_state_publisher import GazeboRosJointStatePublisher
from .gazebo_ros_laser import GazeboRosLaser

REGISTRY = {
    "libgazebo_ros_diff_drive.so": GazeboRosDiffDrive,
    "libgazebo_ros_joint_state_publisher.so": GazeboRosJointStatePublisher,
    "libgazebo_ros_laser.so": GazeboRosLaser,
    "libgazebo_ros_gpu_laser.so": GazeboRosLaser,
}
