"""``joystick_relay.py``: upstream's relay between a joystick teleop and twist_mux. A Twist on ``joy_vel_in``
with linear.x, linear.y and angular.z in [-1, 1] is scaled by the current turbo step and sent on
``joy_vel_out`` while the joystick has priority; ``joy_priority`` (Bool, latched) says whether it has, and a
text marker (``text_marker``, "Manual" or "Autonomous") shows it. Actions as upstream's (twist_mux_msgs):
``joy_priority_action`` toggles the priority, ``joy_turbo_increase``, ``joy_turbo_decrease``,
``joy_turbo_angular_increase``, ``joy_turbo_angular_decrease`` and ``joy_turbo_reset`` step the speeds.

Parameters (private): ``priority`` (default true), ``turbo/steps`` (1), ``turbo/init_step``,
``turbo/linear_forward_min``/``_max``, ``turbo/linear_backward_min``/``_max`` (default the forward ones),
``turbo/linear_lateral_min``/``_max``, ``turbo/angular_min``/``_max`` (1.0 each)."""
import math

import actionlib
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool
from twist_mux_msgs.msg import JoyPriorityAction, JoyTurboAction
from visualization_msgs.msg import Marker


class Velocity:
    """The speed for a joystick value in [-1, 1] at a turbo step: steps spread evenly from min to max."""

    def __init__(self, minimum: float, maximum: float, steps: int):
        self.minimum = minimum
        self.increment = (maximum - minimum) / (steps - 1) if steps > 1 else 0.0

    def __call__(self, value: float, step: int) -> float:
        return value * (self.minimum + self.increment * (step - 1))


def _positive_param(name: str, default: float) -> float:
    value = rospy.get_param(name, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        # Upstream asserts and dies here.
        rospy.logerr(f"parameter {rospy.resolve_name(name)}: must be a finite number > 0, got {value!r}; "
                     f"using {default}")
        return default
    return float(value)


class VelocityControl:
    def __init__(self):
        steps = rospy.get_param("~turbo/steps", 1)
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            rospy.logerr(f"parameter {rospy.resolve_name('~turbo/steps')}: must be an integer >= 1, got "
                         f"{steps!r}; using 1")
            steps = 1
        self.steps = steps
        forward_min = _positive_param("~turbo/linear_forward_min", 1.0)
        forward_max = _positive_param("~turbo/linear_forward_max", 1.0)
        self.forward = Velocity(forward_min, forward_max, steps)
        self.backward = Velocity(_positive_param("~turbo/linear_backward_min", forward_min),
                                 _positive_param("~turbo/linear_backward_max", forward_max), steps)
        self.lateral = Velocity(_positive_param("~turbo/linear_lateral_min", 1.0),
                                _positive_param("~turbo/linear_lateral_max", 1.0), steps)
        self.angular = Velocity(_positive_param("~turbo/angular_min", 1.0),
                                _positive_param("~turbo/angular_max", 1.0), steps)
        default_init = math.floor((steps + 1) / 2.0)
        init_step = rospy.get_param("~turbo/init_step", default_init)
        if isinstance(init_step, bool) or not isinstance(init_step, int) or not 1 <= init_step <= steps:
            rospy.logwarn(f"Initial step {init_step} outside range [1, {steps}]! Falling back to default "
                          f"{default_init}")
            init_step = default_init
        self.init_step = init_step
        self.step = self.angular_step = init_step
        self._complained = set()

    def _invalid(self, command: Twist) -> str:
        values = (command.linear.x, command.linear.y, command.linear.z,
                  command.angular.x, command.angular.y, command.angular.z)
        if not all(math.isfinite(value) for value in values):
            return "Joystick provided non-finite values (NaN or inf)."
        if command.linear.z or command.angular.x or command.angular.y:
            return "Joystick provided invalid values, only linear.x, linear.y and angular.z may be non-zero."
        if abs(command.linear.x) > 1.0 or abs(command.linear.y) > 1.0 or abs(command.angular.z) > 1.0:
            return "Joystick provided invalid values, not in [-1, 1] range."
        return ""

    def scale(self, command: Twist) -> Twist:
        """The scaled Twist; a zero one for invalid input, as upstream (which logs every time; here once a kind)."""
        twist = Twist()
        problem = self._invalid(command)
        if problem:
            if problem not in self._complained:
                self._complained.add(problem)
                rospy.logerr(f"{problem} Sending zero velocity (said once).")
            return twist
        speed = self.forward if command.linear.x >= 0 else self.backward
        twist.linear.x = speed(command.linear.x, self.step)
        twist.linear.y = self.lateral(command.linear.y, self.step)
        twist.angular.z = self.angular(command.angular.z, self.angular_step)
        return twist

    def increase(self):
        self.step = min(self.step + 1, self.steps)
        self.increase_angular()

    def decrease(self):
        self.step = max(self.step - 1, 1)
        self.decrease_angular()

    def increase_angular(self):
        self.angular_step = min(self.angular_step + 1, self.steps)

    def decrease_angular(self):
        self.angular_step = max(self.angular_step - 1, 1)

    def reset(self):
        self.step = self.angular_step = self.init_step


class TextMarker:
    def __init__(self, scale: float = 0.5, z: float = 2.0):
        self.publisher = rospy.Publisher("text_marker", Marker, queue_size=1, latch=True)
        self.marker = Marker(id=0, type=Marker.TEXT_VIEW_FACING)
        self.marker.header.frame_id = "base_footprint"
        self.marker.pose.position.z = z
        self.marker.pose.orientation.w = 1.0
        self.marker.scale.z = scale
        self.marker.color.a = self.marker.color.r = self.marker.color.g = self.marker.color.b = 1.0

    def update(self, joystick_priority: bool):
        self.marker.action = Marker.ADD
        self.marker.text = "Manual" if joystick_priority else "Autonomous"
        self.publisher.publish(self.marker)


class JoystickRelay:
    def __init__(self):
        self.priority = bool(rospy.get_param("~priority", True))
        self.velocity = VelocityControl()
        self.marker = TextMarker()
        self.command_publisher = rospy.Publisher("joy_vel_out", Twist, queue_size=1)
        self.priority_publisher = rospy.Publisher("joy_priority", Bool, queue_size=1, latch=True)
        self.priority_publisher.publish(self.priority)
        self.marker.update(self.priority)
        rospy.Subscriber("joy_vel_in", Twist, self._forward, queue_size=1)
        # The marker is refreshed even when no command comes.
        rospy.Timer(rospy.Duration(1.0), lambda _event: self.marker.update(self.priority))
        # Actions rather than services because joy_teleop calls actions (upstream's reason).
        self.servers = [self._serve("joy_priority_action", JoyPriorityAction, self._toggle_priority)] + [
            self._serve(name, JoyTurboAction, callback) for name, callback in (
                ("joy_turbo_increase", self.velocity.increase), ("joy_turbo_decrease", self.velocity.decrease),
                ("joy_turbo_angular_increase", self.velocity.increase_angular),
                ("joy_turbo_angular_decrease", self.velocity.decrease_angular),
                ("joy_turbo_reset", self.velocity.reset))]

    @staticmethod
    def _serve(name, action_type, callback):
        def execute(_goal):
            callback()
            server.set_succeeded(action_type().action_result.result)
        server = actionlib.SimpleActionServer(name, action_type, execute, auto_start=False)
        server.start()
        return server

    def _forward(self, command: Twist):
        if self.priority:
            self.command_publisher.publish(self.velocity.scale(command))
        self.marker.update(self.priority)

    def _toggle_priority(self):
        self.priority = not self.priority
        rospy.loginfo(f"Toggled joy_priority, current status is: {self.priority}")
        self.priority_publisher.publish(self.priority)
        self.marker.update(self.priority)
        if self.priority:  # the joystick takes over from a stop
            self.command_publisher.publish(Twist())


def main():
    rospy.init_node("joystick_relay")
    JoystickRelay()
    rospy.spin()
