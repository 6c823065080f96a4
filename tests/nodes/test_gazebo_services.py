#!/usr/bin/env python3
"""The /gazebo services beyond the mbot's own (ros_api.test, after test_ros_api.py): each is called through ROS
once with good values and once with each kind of bad value, on a turntable spawned beside the mbot; the answer
is success or upstream's message, and the mbot, a bystander, does not move."""
import math
import unittest

import rospy
import rostest
from gazebo_msgs.srv import ApplyJointEffort, GetLinkState, JointRequest, SpawnModel
from geometry_msgs.msg import Pose

from sim_support import Simulator, print_figures, wait_for

TURNTABLE = """<robot name="table">
  <link name="base_link">
    <inertial><mass value="50"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.6 0.6 0.2"/></geometry></collision>
  </link>
  <link name="plate">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.02"/></geometry></collision>
  </link>
  <joint name="turntable" type="continuous"><parent link="base_link"/><child link="plate"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/></joint>
</robot>"""
PLATE = "table::plate"


def service(name, service_type):
    rospy.wait_for_service("/gazebo/" + name, timeout=30.0)
    return rospy.ServiceProxy("/gazebo/" + name, service_type)


class GazeboServices(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("gazebo_services_test")
        cls.sim = Simulator()
        cls.sim.command(0.0, 0.0)
        spawn = service("spawn_urdf_model", SpawnModel)
        pose = Pose()
        pose.position.x, pose.orientation.w = -2.0, 1.0
        answer = spawn("table", TURNTABLE, "", pose, "world")
        assert answer.success, answer.status_message
        cls.link_state = service("get_link_state", GetLinkState)
        wait_for(lambda: abs(cls.sim.truth()[2].linear.x) < 1e-3, what="the mbot at rest")

    def assert_mbot_still(self, before):
        _, pose, _ = self.sim.truth()
        for axis in "xyz":
            self.assertAlmostEqual(getattr(pose.position, axis), getattr(before.position, axis), delta=1e-4)

    def plate_spin(self):
        return self.link_state(PLATE, "table::base_link").link_state.twist.angular.z

    def test_apply_joint_effort_and_clear_joint_forces(self):
        apply_effort, clear = service("apply_joint_effort", ApplyJointEffort), service("clear_joint_forces",
                                                                                       JointRequest)
        _, mbot, _ = self.sim.truth()
        for joint, effort in (("no_such_joint", 0.01), ("mbot::turntable", 0.01), ("turntable", math.nan),
                              ("turntable", math.inf), ("turntable", -1e300)):
            answer = apply_effort(joint, effort, rospy.Time(0), rospy.Duration(1.0))
            self.assertFalse(answer.success, joint)
            if "no_such" in joint or "mbot" in joint:
                self.assertEqual(answer.status_message, "ApplyJointEffort: joint not found")
            else:
                self.assertIn("joint 'turntable': effort must be finite and at most 1e+06 in size; got ",
                              answer.status_message)
        self.assertLess(abs(self.plate_spin()), 1e-3, "a refused effort moved the plate")
        answer = apply_effort("table::turntable", 0.01, rospy.Time(0), rospy.Duration(-1.0))  # until cleared
        self.assertEqual((answer.success, answer.status_message), (True, "ApplyJointEffort: effort set"))
        wait_for(lambda: self.plate_spin() > 0.2, what="the plate to spin up (1 rad/s² from 0.01 N·m)")
        clear("turntable")
        spin = self.plate_spin()
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 0.2, what="0.2 s of sim time")
        self.assertLess(self.plate_spin(), spin * 1.01 + 1e-3, "the plate still sped up after clear_joint_forces")
        print_figures([f"apply_joint_effort: plate at {spin:.2f} rad/s when cleared, "
                       f"{self.plate_spin():.2f} rad/s 0.2 s later"])
        self.assert_mbot_still(mbot)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "gazebo_services", GazeboServices)
