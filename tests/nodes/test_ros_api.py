#!/usr/bin/env python3
"""The bridge exposes gazebo_ros's ROS API (checked against gazebo_api.yaml through rosgraph, not CLI text),
with one publisher per transform and per joint, and Gazebo's pause and reset behaviour; then the /gazebo services
(gazebo_services.py) and the drive tracking (test_drive_tracking.py) in the same world: rostest starts the launch
again for each <test>."""
import collections
import sys
import time
import unittest

import rosgraph
import rospy
import rosservice
import rostest
import tf2_ros
import yaml
from gazebo_msgs.msg import ModelStates
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from gazebo_services import GazeboServices
from sim_support import Simulator, wait_for
from test_drive_tracking import DriveTracking


class RosApi(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ros_api_test")
        with open(rospy.get_param("~contract")) as contract:
            cls.contract = yaml.safe_load(contract)
        cls.sim = Simulator()
        cls.master = rosgraph.Master("/ros_api_test")

    def test_topics_have_gazebo_types_and_publishers(self):
        def graph_complete():
            publishers, subscribers, _ = self.master.getSystemState()
            publishers, subscribers = dict(publishers), dict(subscribers)
            return all(set(spec.get("publishers", [])) <= set(publishers.get(topic, [])) and
                       set(spec.get("subscribers", [])) <= set(subscribers.get(topic, []))
                       for topic, spec in self.contract["topics"].items())
        wait_for(graph_complete, what="every contract topic to have its publishers and subscribers")
        types = dict(self.master.getTopicTypes())
        for topic, spec in self.contract["topics"].items():
            self.assertEqual(types.get(topic), spec["type"], topic)

    def test_services_have_gazebo_types(self):
        for service, service_type in self.contract["services"].items():
            rospy.wait_for_service(service, timeout=30.0)
            self.assertEqual(rosservice.get_service_type(service), service_type, service)

    def test_tf_tree_is_the_course_tree(self):
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        tree = self.contract["tf_tree"]
        wait_for(lambda: all(buffer.can_transform("odom", child, rospy.Time(0)) for child in tree),
                 what="every frame of the tree to connect to odom")
        frames = yaml.safe_load(buffer.all_frames_as_yaml())
        for child, parent in tree.items():
            self.assertEqual(frames[child]["parent"], parent, child)
        del listener

    def test_one_publisher_per_transform_and_per_joint(self):
        """Gazebo's wheel TF and joint_state_publisher's zeros fight other publishers; here nothing does."""
        transform_senders, joint_senders = collections.defaultdict(set), collections.defaultdict(set)
        joint_positions = collections.defaultdict(list)

        def on_tf(message):
            for transform in message.transforms:
                transform_senders[transform.child_frame_id].add(message._connection_header["callerid"])

        def on_joints(message):
            for name, position in zip(message.name, message.position):
                joint_senders[name].add(message._connection_header["callerid"])
                joint_positions[name].append(position)

        subscribers = [rospy.Subscriber("/tf", TFMessage, on_tf),
                       rospy.Subscriber("/joint_states", JointState, on_joints)]
        self.sim.reset_world()
        self.sim.command(0.3, 0.0)
        self.sim.wait_sim_time(2.0)
        self.sim.command(0.0, 0.0)
        for subscriber in subscribers:
            subscriber.unregister()
        for frame, senders in transform_senders.items():
            self.assertEqual(len(senders), 1, f"/tf child {frame} has several publishers: {senders}")
        self.assertEqual(transform_senders["base_footprint"], {"/gazebo"})
        self.assertEqual(transform_senders["left_wheel_link"], {"/robot_state_publisher"})
        for joint in ("left_wheel_joint", "right_wheel_joint", "back_caster_joint"):
            self.assertEqual(joint_senders[joint], {"/gazebo"}, joint)
        self.assertGreater(max(joint_positions["left_wheel_joint"]), 1.0, "the wheels turned while driving")

    def test_model_states_are_every_models_state(self):
        self.sim.command(0.0, 0.0)
        wait_for(lambda: abs(self.sim.truth()[2].linear.x) < 1e-3 and abs(self.sim.truth()[2].angular.z) < 1e-3,
                 what="the mbot at rest")
        states = rospy.wait_for_message("/gazebo/model_states", ModelStates, timeout=30.0)
        _, pose, _ = self.sim.truth()
        self.assertEqual(states.name, self.sim.world_properties().model_names)
        sent = states.pose[states.name.index("mbot")]
        for axis in "xyz":
            self.assertAlmostEqual(getattr(sent.position, axis), getattr(pose.position, axis), delta=1e-3)
        self.assertAlmostEqual(sent.orientation.z, pose.orientation.z, delta=1e-3)

    def test_the_simulation_keeps_the_worlds_real_time_factor(self):
        """empty.world's real_time_factor is 1: from a reset of sim time (where the pacing starts again), sim time
        never runs ahead of wall time (the pacing's slack is 2 ms), and a machine giving the simulator half a core
        keeps it within half. Counted from the reset, not over a window: after falling behind, the pacing catches
        up."""
        start_wall = time.monotonic()
        self.sim.reset_simulation()
        end_sim = self.sim.wait_sim_time(3.0)[0]
        ratio = end_sim / (time.monotonic() - start_wall)
        print(f"figure: empty world at real_time_factor 1: {ratio:.3f} s of sim time per wall second",
              file=sys.stderr)
        self.assertLess(ratio, 1.05)
        self.assertGreater(ratio, 0.5)

    def test_paused_means_no_clock_and_reset_simulation_rewinds_it(self):
        clocks = []
        subscriber = rospy.Subscriber("/clock", Clock, lambda message: clocks.append(message.clock.to_sec()))
        wait_for(lambda: len(clocks) > 10, what="/clock messages")
        self.sim.pause()
        self.addCleanup(self.sim.unpause)  # whatever fails below: the cases after this one need the clock
        paused_at = len(clocks)
        # Twenty answers of the simulator itself, each measured in one of its loop passes: a running simulator
        # steps between any two of them, a paused one gives one time throughout, and /clock stays put.
        times = {self.sim.truth()[0] for _ in range(20)}
        self.assertEqual(len(times), 1, f"sim time went on while paused: {sorted(times)}")
        self.assertLessEqual(len(clocks) - paused_at, 1, "/clock went on while paused")
        self.sim.unpause()
        wait_for(lambda: len(clocks) > paused_at + 10, what="/clock to resume after unpause")
        before = clocks[-1]
        self.sim.reset_simulation()
        wait_for(lambda: clocks[-1] < before, what="/clock to go back after reset_simulation")
        self.assertLess(clocks[-1], 1.0)
        subscriber.unregister()


def load_tests(loader, tests, pattern):
    """The services, this module's cases, then the drive tracking: it takes the pacing off, which
    test_the_simulation_keeps_the_worlds_real_time_factor needs."""
    return unittest.TestSuite(loader.loadTestsFromTestCase(case) for case in (GazeboServices, RosApi, DriveTracking))


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "ros_api", "__main__")
