"""The /gazebo services beyond the mbot's own, run by test_ros_api.py in its world (a rostest <test> of their own
would launch the world again): each is called through ROS
once with good values and once with each kind of bad value, on a turntable spawned beside the mbot; the answer
is success or upstream's message, and the mbot, a bystander, does not move."""
import math
import os
import unittest

import rospy
from dynamic_reconfigure.msg import Config, ConfigDescription, DoubleParameter
from dynamic_reconfigure.srv import Reconfigure
from gazebo_msgs.msg import LinkState, LinkStates, ModelState, ODEJointProperties, PerformanceMetrics
from gazebo_msgs.srv import (ApplyJointEffort, DeleteLight, GetJointProperties, GetLightProperties, GetLinkProperties,
                             GetLinkState, GetModelState, GetPhysicsProperties, JointRequest, SetJointProperties,
                             SetLightProperties, SetLinkProperties, SetLinkState, SetPhysicsProperties, SpawnModel)
from geometry_msgs.msg import Pose, Vector3
from std_msgs.msg import ColorRGBA

from sim_support import Simulator, print_figures, wait_for

with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "urdf", "turntable.urdf")) as turntable:
    TURNTABLE = turntable.read()
PLATE = "table::plate"


def service(name, service_type):
    rospy.wait_for_service("/gazebo/" + name, timeout=30.0)
    return rospy.ServiceProxy("/gazebo/" + name, service_type)


class GazeboServices(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ros_api_test")  # test_ros_api.py's node: one node per process
        cls.sim = Simulator()
        cls.sim.command(0.0, 0.0)
        spawn = service("spawn_urdf_model", SpawnModel)
        pose = Pose()
        pose.position.x, pose.orientation.w = -2.0, 1.0
        # In a namespace of its own: its joint_states are not the mbot's robot_state_publisher's.
        answer = spawn("table", TURNTABLE, "/table", pose, "world")
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

    def link_position(self, link):
        position = self.link_state(link, "").link_state.pose.position
        return position.x, position.y, position.z

    def test_set_link_state_and_the_state_topics(self):
        set_link = service("set_link_state", SetLinkState)
        _, mbot, _ = self.sim.truth()
        before = self.link_position("table::base_link")
        for link, frame, value, message in (
                ("table::lid", "", 1.0, "SetLinkState: link does not exist"),
                ("plate", "", 1.0, "SetLinkState: link does not exist"),
                ("table::base_link", "nowhere", 1.0, "SetLinkState: failed"),
                ("table::base_link", "", math.nan, "position.x is nan, not a finite number"),
                ("table::base_link", "", math.inf, "position.x is inf, not a finite number"),
                ("table::base_link", "", 1e300, "position.x = 1e+300 is outside")):
            state = LinkState(link_name=link, reference_frame=frame)
            state.pose.position.x, state.pose.orientation.w = value, 1.0
            answer = set_link(state)
            self.assertFalse(answer.success, (link, frame, value))
            self.assertIn(message, answer.status_message)
        for got, expected in zip(self.link_position("table::base_link"), before):
            self.assertAlmostEqual(got, expected, delta=1e-4)
        # In the mbot's frame: 2 m ahead of it, 0.3 m up (where it falls from).
        state = LinkState(link_name="table::base_link", reference_frame="mbot")
        state.pose.position.x, state.pose.position.z, state.pose.orientation.w = 2.0, 0.3, 1.0
        self.assertEqual(set_link(state).status_message, "SetLinkState: success")
        relative = service("get_model_state", GetModelState)("table", "mbot")
        self.assertAlmostEqual(relative.pose.position.x, 2.0, delta=1e-3)
        self.assertEqual(service("get_model_state", GetModelState)("table", "table::lid").status_message,
                         "GetModelState: reference relative_entity_name not found, did you forget to scope the body "
                         "by model name?")
        plate = service("get_model_state", GetModelState)("mbot", "table::plate")
        self.assertTrue(plate.success, plate.status_message)
        # The topics take the same requests.
        model_topic = rospy.Publisher("/gazebo/set_model_state", ModelState, queue_size=1, latch=True)
        link_topic = rospy.Publisher("/gazebo/set_link_state", LinkState, queue_size=1, latch=True)
        moved = ModelState(model_name="table")
        moved.pose.position.x, moved.pose.position.y, moved.pose.position.z = -3.0, 0.0, 0.3
        moved.pose.orientation.w = 1.0
        model_topic.publish(moved)
        wait_for(lambda: abs(self.link_position("table::base_link")[0] + 3.0) < 0.01,
                 what="the table at x = -3 from /gazebo/set_model_state")
        state = LinkState(link_name="table::base_link")
        state.pose.position.x, state.pose.position.y, state.pose.position.z = -3.0, 2.0, 0.3
        state.pose.orientation.w = 1.0
        link_topic.publish(state)
        wait_for(lambda: abs(self.link_position("table::base_link")[1] - 2.0) < 0.01,
                 what="the table at y = 2 from /gazebo/set_link_state")
        states = rospy.wait_for_message("/gazebo/link_states", LinkStates, timeout=30.0)
        self.assertIn("mbot::base_footprint", states.name)
        self.assertAlmostEqual(states.pose[states.name.index("table::base_link")].position.y, 2.0, delta=0.01)
        self.assert_mbot_still(mbot)

    def test_joint_and_link_properties(self):
        get_link, set_link = service("get_link_properties", GetLinkProperties), service("set_link_properties",
                                                                                       SetLinkProperties)
        get_joint, set_joint = service("get_joint_properties", GetJointProperties), service("set_joint_properties",
                                                                                          SetJointProperties)
        _, mbot, _ = self.sim.truth()
        plate = get_link("table::plate")
        self.assertEqual((plate.success, plate.status_message, plate.mass), (True, "GetLinkProperties: got properties",
                                                                            1.0))
        self.assertEqual(get_link("plate").status_message,
                         "GetLinkProperties: link not found, did you forget to scope the link by model name?")
        fields = dict(com=plate.com, gravity_mode=True, ixx=plate.ixx, ixy=0.0, ixz=0.0, iyy=plate.iyy, iyz=0.0,
                      izz=plate.izz)
        for link, mass, message in (("table::lid", 1.0, "SetLinkProperties: link not found"),
                                    ("table::plate", math.nan, "mass must be finite, above 0"),
                                    ("table::plate", math.inf, "mass must be finite, above 0"),
                                    ("table::plate", 1e300, "mass must be finite, above 0")):
            answer = set_link(link_name=link, mass=mass, **fields)
            self.assertFalse(answer.success, (link, mass))
            self.assertIn(message, answer.status_message)
        self.assertEqual(get_link("table::plate").mass, 1.0)
        self.assertEqual(set_link(link_name="table::plate", mass=2.0, **fields).status_message,
                         "SetLinkProperties: properties set")
        self.assertEqual(get_link("table::plate").mass, 2.0)
        joint = get_joint("turntable")
        self.assertEqual((joint.success, joint.status_message, joint.type, joint.damping),
                         (True, "GetJointProperties: got properties", joint.CONTINUOUS, (0.0,)))
        self.assertEqual(get_joint("no_such_joint").status_message, "GetJointProperties: joint not found")
        for name, damping, message in (("no_such_joint", 0.1, "SetJointProperties: joint not found"),
                                       ("turntable", math.nan, "damping must be finite"),
                                       ("turntable", math.inf, "damping must be finite"),
                                       ("turntable", 1e300, "damping must be finite")):
            answer = set_joint(name, ODEJointProperties(damping=[damping]))
            self.assertFalse(answer.success, (name, damping))
            self.assertIn(message, answer.status_message)
        self.assertEqual(set_joint("table::turntable", ODEJointProperties(damping=[0.5])).status_message,
                         "SetJointProperties: properties set")
        self.assertEqual(get_joint("turntable").damping, (0.5,))
        self.assert_mbot_still(mbot)

    def test_physics_properties(self):
        get, set_physics = service("get_physics_properties", GetPhysicsProperties), service(
            "set_physics_properties", SetPhysicsProperties)
        world = get()
        self.assertEqual((world.status_message, world.ode_config.sor_pgs_iters, world.ode_config.erp),
                         ("GetPhysicsProperties: got properties", 50, 0.2))
        _, mbot, _ = self.sim.truth()
        gravity = world.gravity
        for time_step, z, message in ((math.nan, -9.8, "time_step must be finite"),
                                      (1e300, -9.8, "time_step must be finite"),
                                      (0.001, math.inf, "gravity.z must be finite"),
                                      (0.001, -1e300, "gravity.z must be finite")):
            gravity.z = z
            answer = set_physics(time_step, world.max_update_rate, gravity, world.ode_config)
            self.assertFalse(answer.success)
            self.assertIn(message, answer.status_message)
        self.assertEqual(get().gravity.z, -9.8)
        gravity.z = -5.0
        answer = set_physics(world.time_step, world.max_update_rate, gravity, world.ode_config)
        self.assertEqual((answer.success, answer.status_message), (True, "physics engine updated"))
        self.assertEqual(get().gravity.z, -5.0)
        # The physics dynamic_reconfigure takes the same: a change, then a value the physics refuses.
        reconfigure = service("set_parameters", Reconfigure)
        description = rospy.wait_for_message("/gazebo/parameter_descriptions", ConfigDescription, timeout=30.0)
        self.assertIn("contact_max_correcting_vel", [item.name for item in description.groups[0].parameters])

        def gravity_z(answer):
            return next(item.value for item in answer.config.doubles if item.name == "gravity_z")
        self.assertEqual(gravity_z(reconfigure(Config(doubles=[DoubleParameter("gravity_z", -6.0)]))), -6.0)
        self.assertEqual((get().gravity.z, rospy.get_param("/gazebo/gravity_z")), (-6.0, -6.0))
        refused = reconfigure(Config(doubles=[DoubleParameter("gravity_z", math.nan)]))
        self.assertEqual(gravity_z(refused), -6.0)
        self.assertEqual(get().gravity.z, -6.0)
        updates = rospy.wait_for_message("/gazebo/parameter_updates", Config, timeout=30.0)
        self.assertEqual(next(item.value for item in updates.doubles if item.name == "gravity_z"), -6.0)
        gravity.z = -9.8  # back, for the tests that follow in this world
        self.assertTrue(set_physics(world.time_step, world.max_update_rate, gravity, world.ode_config).success)
        self.assert_mbot_still(mbot)

    def test_lights_and_performance_metrics(self):
        get, set_light, delete = (service("get_light_properties", GetLightProperties),
                                  service("set_light_properties", SetLightProperties),
                                  service("delete_light", DeleteLight))
        sun = get("sun")  # empty.world's model://sun, as Gazebo's
        self.assertEqual(sun.success, True)
        self.assertAlmostEqual(sun.diffuse.r, 0.8, places=6)  # ColorRGBA is float32
        self.assertEqual(sun.attenuation_constant, 0.9)
        self.assertEqual(get("lamp").status_message, "getLightProperties: Requested light lamp not found!")
        pose = Pose()
        pose.orientation.w = 1.0
        for light, value, message in (("lamp", 0.5, "setLightProperties: Requested light lamp not found!"),
                                      ("sun", math.nan, "diffuse must be finite"),
                                      ("sun", math.inf, "diffuse must be finite"),
                                      ("sun", 1e30, "diffuse must be finite")):  # float32: 1e300 is unsendable
            answer = set_light(light, True, ColorRGBA(value, 0.0, 0.0, 1.0), ColorRGBA(), 1.0, 0.0, 0.0,
                               Vector3(-0.5, 0.1, -0.9), pose)
            self.assertFalse(answer.success, (light, value))
            self.assertIn(message, answer.status_message)
        self.assertAlmostEqual(get("sun").diffuse.r, 0.8, places=6)
        self.assertTrue(set_light("sun", True, ColorRGBA(0.5, 0.5, 0.5, 1.0), ColorRGBA(), 1.0, 0.0, 0.0,
                                  Vector3(-0.5, 0.1, -0.9), pose).success)
        self.assertEqual(get("sun").diffuse.r, 0.5)
        self.assertEqual(delete("sun").status_message, "DeleteLight: sun successfully deleted")
        self.assertEqual(delete("sun").status_message, "DeleteLight: Requested light sun not found!")
        metrics = rospy.wait_for_message("/gazebo/performance_metrics", PerformanceMetrics, timeout=30.0)
        print_figures([f"performance_metrics: real_time_factor {metrics.real_time_factor:.3f}"])
        # The arithmetic is unit-tested; here it comes through ROS. Over one wall second a loaded machine makes it
        # anything from a crawl to a catch-up sprint (the pacing makes up for lost time), so only its sign is sure.
        self.assertGreater(metrics.real_time_factor, 0.0)
        self.assertAlmostEqual(metrics.header.stamp.to_sec(), rospy.get_time(), delta=2.0)
