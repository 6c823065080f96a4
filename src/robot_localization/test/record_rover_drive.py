#!/usr/bin/env python3
"""Records the rover's sensor data and ground truth over a 10 m drive with turns, for the filter's unit test.

Run it against the rover's simulation (`./mbot sim rover lidar_3d_enabled:=false`, any ROS master):
    python3 record_rover_drive.py data/rover_drive.npz
It drives through rover_velocity_controller/cmd_vel on sim time (straights, arcs both ways and a turn in place),
and saves the diff drive odometry, the hector IMU, the base_link -> imu_link mounting and /gazebo/model_states'
pose of the rover (every 0.05 s of sim time, and once at rest at the end). Covariances are stored once per topic:
both sources publish constant ones, which the recorder checks."""
import sys

import numpy as np
import rospy
import tf2_ros
from gazebo_msgs.msg import ModelStates
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

# (seconds of sim time, forward m/s, yaw rad/s): about 10.5 m of path with turns both ways.
DRIVE = [(4.0, 0.5, 0.0), (3.14, 0.5, 0.5), (4.0, 0.5, 0.0), (3.14, 0.5, -0.5), (3.14, 0.0, 0.5),
         (4.0, 0.5, 0.0), (2.0, 0.4, -0.8), (2.0, 0.5, 0.0), (2.0, 0.0, 0.0)]
TRUTH_PERIOD = 0.05


def xyz(v):
    return [v.x, v.y, v.z]


def xyzw(q):
    return [q.x, q.y, q.z, q.w]


class Recorder:
    def __init__(self):
        self.odometry, self.imu, self.truth = [], [], []
        self.covariances = {}
        self.frames = {}
        rospy.Subscriber("rover_velocity_controller/odom", Odometry, self.on_odometry, queue_size=100)
        rospy.Subscriber("imu/data", Imu, self.on_imu, queue_size=100)
        rospy.Subscriber("/gazebo/model_states", ModelStates, self.on_model_states, queue_size=10)

    def constant(self, name, values):
        values = np.array(values, dtype=float)
        stored = self.covariances.setdefault(name, values)
        if not np.array_equal(stored, values):
            raise SystemExit(f"{name} changed during the recording; the data format stores it once")

    def on_odometry(self, message):
        self.frames.update(odometry_frame=message.header.frame_id, odometry_child_frame=message.child_frame_id)
        self.constant("odometry_pose_covariance", message.pose.covariance)
        self.constant("odometry_twist_covariance", message.twist.covariance)
        self.odometry.append([message.header.stamp.to_sec(), *xyz(message.pose.pose.position),
                              *xyzw(message.pose.pose.orientation), *xyz(message.twist.twist.linear),
                              *xyz(message.twist.twist.angular)])

    def on_imu(self, message):
        self.frames.update(imu_frame=message.header.frame_id)
        self.constant("imu_orientation_covariance", message.orientation_covariance)
        self.constant("imu_angular_velocity_covariance", message.angular_velocity_covariance)
        self.constant("imu_linear_acceleration_covariance", message.linear_acceleration_covariance)
        self.imu.append([message.header.stamp.to_sec(), *xyzw(message.orientation),
                         *xyz(message.angular_velocity), *xyz(message.linear_acceleration)])

    def on_model_states(self, message):
        now = rospy.Time.now().to_sec()
        if "rover" in message.name and (not self.truth or now - self.truth[-1][0] >= TRUTH_PERIOD):
            pose = message.pose[message.name.index("rover")]
            self.truth.append([now, *xyz(pose.position), *xyzw(pose.orientation)])


def main(path):
    rospy.init_node("record_rover_drive")
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    mounting = buffer.lookup_transform("base_link", "imu_link", rospy.Time(0), rospy.Duration(30.0)).transform
    command = rospy.Publisher("rover_velocity_controller/cmd_vel", Twist, queue_size=1)
    recorder = Recorder()
    rate = rospy.Rate(20)
    while not rospy.is_shutdown() and (command.get_num_connections() == 0 or len(recorder.imu) < 50):
        rate.sleep()
    for duration, forward, turn in DRIVE:
        end = rospy.Time.now() + rospy.Duration(duration)
        twist = Twist()
        twist.linear.x, twist.angular.z = forward, turn
        while not rospy.is_shutdown() and rospy.Time.now() < end:
            command.publish(twist)
            rate.sleep()
    np.savez_compressed(
        path, odometry=np.array(recorder.odometry), imu=np.array(recorder.imu), truth=np.array(recorder.truth),
        imu_mounting=np.array([*xyz(mounting.translation), *xyzw(mounting.rotation)]),
        frames=np.array([recorder.frames[name] for name in ("odometry_frame", "odometry_child_frame", "imu_frame")]),
        **recorder.covariances)
    print(f"{len(recorder.odometry)} odometry, {len(recorder.imu)} IMU, {len(recorder.truth)} ground truth "
          f"samples in {path}")


if __name__ == "__main__":
    main(sys.argv[1])
