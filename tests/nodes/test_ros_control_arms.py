#!/usr/bin/env python3
"""Two-joint arms reach position setpoints within a degree through ros_control: /effort_arm with
effort_controllers/JointPositionController (PID to effort), /position_arm with
position_controllers/JointGroupPositionController. Joint angles come from each arm's joint_state_controller; the
PID controllers' control_msgs/JointControllerState follows their setpoint and joint at a tenth of the control rate."""
import math
import unittest

import rospy
import rostest
from control_msgs.msg import JointControllerState
from controller_manager_msgs.srv import ListControllers
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray

from sim_support import WALL_TIMEOUT, print_figures, wait_for

SETPOINTS = ((0.5, -0.8), (-1.0, 1.2), (1.5, 0.3))
TOLERANCE_DEGREES = 1.0


class RosControlArms(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("ros_control_arms_test")
        cls.figures = []
        cls.states = {}
        for arm, controllers in (("effort_arm", 3), ("position_arm", 2)):
            service = f"/{arm}/controller_manager/list_controllers"
            rospy.wait_for_service(service, timeout=WALL_TIMEOUT)
            listing = rospy.ServiceProxy(service, ListControllers)
            wait_for(lambda: [c.state for c in listing().controller] == ["running"] * controllers,
                     what=f"the {arm} spawner to start its controllers")
            rospy.Subscriber(f"/{arm}/joint_states", JointState,
                             lambda message, arm=arm: cls.states.__setitem__(arm, message))
        wait_for(lambda: len(cls.states) == 2, what="joint_states of both arms")

    @classmethod
    def tearDownClass(cls):
        print_figures(cls.figures)

    def errors(self, arm, setpoint):
        state = self.states[arm]
        positions = dict(zip(state.name, state.position))
        return [math.degrees(abs(positions[joint] - target)) for joint, target in zip(("shoulder", "elbow"), setpoint)]

    def reach(self, arm, setpoint):
        """Wait (sim time passes at its own pace) until both joints are within tolerance; return the errors."""
        wait_for(lambda: max(self.errors(arm, setpoint)) < TOLERANCE_DEGREES, timeout=WALL_TIMEOUT,
                 what=f"{arm} to reach {setpoint}")
        # Still there a second of sim time later: settled, not passing through.
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 1.0, what="1 s of sim time")
        errors = self.errors(arm, setpoint)
        self.assertLess(max(errors), TOLERANCE_DEGREES, f"{arm} at {setpoint}: errors {errors} degrees")
        return errors

    def test_effort_arm_through_pid_position_controllers(self):
        shoulder = rospy.Publisher("/effort_arm/shoulder_position_controller/command", Float64, queue_size=1,
                                   latch=True)
        elbow = rospy.Publisher("/effort_arm/elbow_position_controller/command", Float64, queue_size=1, latch=True)
        for setpoint in SETPOINTS:
            shoulder.publish(Float64(setpoint[0]))
            elbow.publish(Float64(setpoint[1]))
            errors = self.reach("effort_arm", setpoint)
            self.figures.append(f"effort arm (effort_controllers/JointPositionController) at {setpoint} rad: errors "
                                f"{errors[0]:.3f}, {errors[1]:.3f} degrees")

    def test_pid_controller_state_follows_the_setpoint(self):
        states = []
        subscriber = rospy.Subscriber("/effort_arm/elbow_position_controller/state", JointControllerState,
                                      states.append)
        wait_for(lambda: len(states) >= 20, what="twenty elbow controller states")
        subscriber.unregister()
        state = states[-1]
        stamps = [message.header.stamp.to_sec() for message in states[-10:]]
        period = (stamps[-1] - stamps[0]) / 9
        positions = dict(zip(self.states["effort_arm"].name, self.states["effort_arm"].position))
        self.figures.append(f"elbow controller state: set point {state.set_point:.3f}, process value "
                            f"{state.process_value:.3f}, every {period * 1000:.1f} ms, p {state.p:g}")
        self.assertAlmostEqual(state.process_value, positions["elbow"], delta=0.05)
        self.assertAlmostEqual(state.error, state.set_point - state.process_value, delta=1e-9)
        self.assertAlmostEqual(period, 10 * state.time_step, delta=1e-6)  # every tenth control update
        self.assertGreater(state.p, 0.0)

    def test_non_finite_commands_on_the_topics_are_ignored(self):
        """NaN and inf on the command topics leave both arms where they were; 1e308 is taken as the joint limit."""
        shoulder = rospy.Publisher("/effort_arm/shoulder_position_controller/command", Float64, queue_size=1,
                                   latch=True)
        group = rospy.Publisher("/position_arm/arm_controller/command", Float64MultiArray, queue_size=1, latch=True)
        shoulder.publish(Float64(0.5))
        group.publish(Float64MultiArray(data=[0.5, -0.8]))
        self.reach("effort_arm", (0.5, self.positions("effort_arm")["elbow"]))
        self.reach("position_arm", (0.5, -0.8))
        for value in (math.nan, math.inf, -math.inf):
            shoulder.publish(Float64(value))
            group.publish(Float64MultiArray(data=[value, value]))
            start = rospy.get_time()
            wait_for(lambda: rospy.get_time() > start + 0.5, what="0.5 s of sim time")
            self.assertAlmostEqual(self.positions("effort_arm")["shoulder"], 0.5, delta=math.radians(TOLERANCE_DEGREES))
            self.assertLess(max(self.errors("position_arm", (0.5, -0.8))), TOLERANCE_DEGREES, value)
        # Taken as the URDF's upper limit, 2.0 rad; the 40 N m shoulder holds the arm against gravity at 1.9.
        shoulder.publish(Float64(1e308))
        wait_for(lambda: self.positions("effort_arm")["shoulder"] > 1.5, timeout=WALL_TIMEOUT,
                 what="the effort arm's shoulder on its way to the upper limit")
        self.assertTrue(all(math.isfinite(v) for arm in self.states.values() for v in arm.position + arm.velocity))

    def positions(self, arm):
        state = self.states[arm]
        return dict(zip(state.name, state.position))

    def test_position_arm_through_the_forward_group_controller(self):
        command = rospy.Publisher("/position_arm/arm_controller/command", Float64MultiArray, queue_size=1,
                                  latch=True)
        for setpoint in SETPOINTS:
            command.publish(Float64MultiArray(data=list(setpoint)))
            errors = self.reach("position_arm", setpoint)
            self.figures.append(f"position arm (position_controllers/JointGroupPositionController) at {setpoint} rad: "
                                f"errors {errors[0]:.3f}, {errors[1]:.3f} degrees")


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "ros_control_arms", RosControlArms)
