"""Helpers shared by the rostest nodes: waiting on conditions, ground truth, driving through /cmd_vel."""
import math
import sys

import rospy
from controller_manager_msgs.srv import ListControllers
from gazebo_msgs.srv import GetModelState, GetPhysicsProperties, GetWorldProperties, SetPhysicsProperties
from geometry_msgs.msg import Twist
from mbot_sim_bridge.processes import wait_until
from std_srvs.srv import Empty

# Wall-clock limits: generous, because CI machines are slow; a test fails only if a condition never comes.
WALL_TIMEOUT = 60.0


def wait_for(condition, timeout=WALL_TIMEOUT, what="condition"):
    """``condition``'s truthy value, polled for at most ``timeout`` wall seconds (then AssertionError)."""
    return wait_until(condition, timeout, what)


def init_test_node(name):
    """rospy.init_node, once per process: a test node may run the test cases of several modules on one launch."""
    if not rospy.core.is_initialized():
        rospy.init_node(name)


def twist(linear=0.0, angular=0.0) -> Twist:
    """A planar base's command: linear.x and angular.z."""
    message = Twist()
    message.linear.x, message.angular.z = linear, angular
    return message


def publish_for(sim_seconds, *publications):
    """Each (publisher, message) every 20 ms of wall time for ``sim_seconds`` of sim time: well within the
    controllers' cmd_vel timeouts (0.25 s and more)."""
    end = rospy.get_time() + sim_seconds
    while rospy.get_time() < end:
        for publisher, message in publications:
            publisher.publish(message)
        rospy.rostime.wallsleep(0.02)


def print_figures(lines):
    """A test's measurements, one ``figure:`` line each on stderr, where ./mbot test picks them up."""
    print("\n".join([""] + ["figure: " + line for line in lines]), file=sys.stderr)


def model_state_service():
    """/gazebo/get_model_state on one connection kept open: tests poll it every 20 ms, and a connection per call
    (a master lookup, a socket and a server thread) costs the master, the simulator and the test more CPU than
    the answer. One thread at a time may call it."""
    rospy.wait_for_service("/gazebo/get_model_state", timeout=WALL_TIMEOUT)
    return rospy.ServiceProxy("/gazebo/get_model_state", GetModelState, persistent=True)


def run_unpaced():
    """Physics as fast as the machine goes (max_update_rate 0), as a Gazebo user sets it through
    /gazebo/set_physics_properties. Not for tests that repeat a command on wall time against a timeout."""
    rospy.wait_for_service("/gazebo/set_physics_properties", timeout=WALL_TIMEOUT)
    physics = rospy.ServiceProxy("/gazebo/get_physics_properties", GetPhysicsProperties)()
    answer = rospy.ServiceProxy("/gazebo/set_physics_properties", SetPhysicsProperties)(
        physics.time_step, 0.0, physics.gravity, physics.ode_config)
    assert answer.success, answer.status_message


def controller_states(list_controllers) -> dict:
    """controller name -> state, from a controller_manager/list_controllers service proxy."""
    return {state.name: state.state for state in list_controllers().controller}


def wait_for_running_controllers(names, manager="/controller_manager"):
    """Wait until the controller manager lists exactly ``names``, all running (the spawner has done its work)."""
    service = manager + "/list_controllers"
    rospy.wait_for_service(service, timeout=WALL_TIMEOUT)
    listing = rospy.ServiceProxy(service, ListControllers)
    wait_for(lambda: controller_states(listing) == {name: "running" for name in names},
             what="the spawner to start " + ", ".join(names))


def yaw_of(orientation):
    q = orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def roll_pitch_of(orientation):
    q = orientation
    roll = math.atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (q.w * q.y - q.z * q.x))))
    return roll, pitch


def motion_between(start, end):
    """(speed along the start heading, yaw rate) between two ground truths of ``Simulator.truth()``."""
    (t0, pose0, twist0), (t1, pose1, twist1) = start, end
    dt = t1 - t0
    heading = yaw_of(pose0.orientation)
    dx, dy = pose1.position.x - pose0.position.x, pose1.position.y - pose0.position.y
    turned = math.remainder(yaw_of(pose1.orientation) - heading, 2 * math.pi)
    # A loaded machine may answer seconds of sim time late, so the poses alone hide whole turns: the
    # physics' own angular velocity counts them.
    whole_turns = round((0.5 * (twist0.angular.z + twist1.angular.z) * dt - turned) / (2 * math.pi))
    return (dx * math.cos(heading) + dy * math.sin(heading)) / dt, (turned + 2 * math.pi * whole_turns) / dt


class Simulator:
    """The bridge seen through gazebo_ros's services, and the robot through /cmd_vel (None: a robot without)."""

    def __init__(self, model="mbot", cmd_vel="/cmd_vel"):
        self.model = model
        for service in ("get_model_state", "get_world_properties", "reset_world", "pause_physics",
                        "unpause_physics", "reset_simulation"):
            rospy.wait_for_service("/gazebo/" + service, timeout=WALL_TIMEOUT)
        self.get_model_state = model_state_service()
        self.world_properties = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        self.reset_world = rospy.ServiceProxy("/gazebo/reset_world", Empty)
        self.reset_simulation = rospy.ServiceProxy("/gazebo/reset_simulation", Empty)
        self.pause = rospy.ServiceProxy("/gazebo/pause_physics", Empty)
        self.unpause = rospy.ServiceProxy("/gazebo/unpause_physics", Empty)
        wait_for(lambda: model in self.world_properties().model_names, what=f"model '{model}' to be spawned")
        if cmd_vel:
            self.cmd_vel = rospy.Publisher(cmd_vel, Twist, queue_size=1, latch=True)
            wait_for(lambda: self.cmd_vel.get_num_connections() > 0, what=f"the simulator to subscribe {cmd_vel}")

    def truth(self):
        """(sim time, pose, twist) of the model, measured in one step of the simulator."""
        state = self.get_model_state(self.model, "world")
        assert state.success, state.status_message
        return state.header.stamp.to_sec(), state.pose, state.twist

    def command(self, linear=0.0, angular=0.0):
        self.cmd_vel.publish(twist(linear, angular))

    def wait_sim_time(self, seconds):
        """Wait until ``seconds`` of sim time have passed; returns the ground truth then."""
        start = self.truth()[0]
        # On this node's clock first (no call to the simulator), then the truth, measured at that time or later.
        wait_for(lambda: rospy.get_time() >= start + seconds, what=f"{seconds:.1f} s of sim time")
        return wait_for(lambda: (lambda truth: truth if truth[0] >= start + seconds else None)(self.truth()),
                        what=f"{seconds:.1f} s of sim time")
