"""ROS side of the keyboard teleop: ~params, the cmd_vel publisher and the key loop."""

import collections
import math
import signal
import sys
import warnings

import rospy
from geometry_msgs.msg import Twist

from mbot_teleop.keymap import HELP
from mbot_teleop.teleop import CYCLE_PERIOD, KeyAction, Teleop, idle_limit_for
from mbot_teleop.terminal import raw_mode, read_key

NODE_NAME = 'mbot_teleop'
NOT_A_TERMINAL = ('mbot_teleop: stdin is not a terminal; run it from a terminal: '
                  'rosrun mbot_teleop mbot_teleop.py')

# The course script's own values; its launch file passes 0.1 and 0.4.
DEFAULT_SPEED = 0.2  # m/s
DEFAULT_TURN = 1.0  # rad/s
# Five idle cycles, the course's idle stop.
DEFAULT_KEY_TIMEOUT = 0.5  # s
# The course reprints the help with every 15th speed line, so the keys stay on screen.
HELP_EVERY = 15

Params = collections.namedtuple('Params', 'speed speed_from turn turn_from key_timeout')


class ParamError(ValueError):
    """A ~param holds a value the teleop cannot use."""


def _number(name, value, allow_zero=False):
    """Return value as a float if it is a finite number > 0 (or == 0 when allowed)."""
    if (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            and (value > 0 or (allow_zero and value == 0))):
        return float(value)
    bound = '>= 0' if allow_zero else '> 0'
    raise ParamError(f'~{name} must be a number {bound}, got {value!r}')


def _scale(name, course_name, default):
    """Read ~name, else the course's ~course_name, else default; return (value, source)."""
    found = [param for param in (name, course_name) if rospy.has_param('~' + param)]
    if not found:
        return default, 'default'
    if len(found) == 2:
        rospy.logwarn(f"{NODE_NAME}: ~{name} is set, so ~{course_name} is ignored")
    return _number(found[0], rospy.get_param('~' + found[0])), '~' + found[0]


def read_params():
    """Read every ~param once; raise ParamError on a bad value."""
    speed, speed_from = _scale('speed', 'scale_linear', DEFAULT_SPEED)
    turn, turn_from = _scale('turn', 'scale_angular', DEFAULT_TURN)
    key_timeout = _number('key_timeout', rospy.get_param('~key_timeout', DEFAULT_KEY_TIMEOUT),
                          allow_zero=True)
    return Params(speed, speed_from, turn, turn_from, key_timeout)


def speeds_line(teleop):
    """The course's status line; rounding hides float noise such as 0.22000000000000003."""
    return f'currently:\tspeed {round(teleop.speed, 4)}\tturn {round(teleop.turn, 4)}'


def _twist(linear, angular):
    twist = Twist()
    twist.linear.x = linear
    twist.angular.z = angular
    return twist


def _run(teleop, publisher, fd):
    """Poll keys and publish one Twist per cycle until CTRL-C or ROS shutdown."""
    print(HELP)
    print(speeds_line(teleop))
    speed_lines = 0
    while not rospy.is_shutdown():
        action = teleop.cycle(read_key(fd, CYCLE_PERIOD))
        if action is KeyAction.QUIT:
            return
        if action is KeyAction.SPEED:
            print(speeds_line(teleop))
            speed_lines += 1
            if speed_lines % HELP_EVERY == 0:
                print(HELP)
        publisher.publish(_twist(teleop.linear, teleop.angular))


def main():
    """Run the teleop on the terminal at stdin; return the exit status."""
    if sys.stdin is None or not sys.stdin.isatty():
        print(NOT_A_TERMINAL, file=sys.stderr)
        return 1

    # rospy's handlers would shut the node down before the zero Twist goes out, so
    # INT, TERM (roslaunch's escalation) and HUP (terminal closed) all unwind main instead.
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, signal.default_int_handler)
    try:
        rospy.init_node(NODE_NAME, disable_signals=True)
        params = read_params()
    except KeyboardInterrupt:
        # Stopped while init_node waited for the master: nothing moved, nothing to restore.
        rospy.signal_shutdown('interrupted while starting')
        return 1
    except ParamError as error:
        rospy.logfatal(f"{NODE_NAME}: {error}")
        rospy.signal_shutdown('bad parameter')
        return 1
    # Synchronous (queue_size=None): each Twist is on the wire when publish() returns, so keys typed ahead
    # are never dropped and the zero Twist on exit is sent before the node shuts down. rospy warns about
    # that choice, which here is deliberate.
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', SyntaxWarning)
        publisher = rospy.Publisher('cmd_vel', Twist, queue_size=None)
    rospy.loginfo(f"{NODE_NAME}: speed {params.speed:g} m/s ({params.speed_from}), turn {params.turn:g} rad/s "
                  f"({params.turn_from}), key_timeout {params.key_timeout:g} s, publishing on "
                  f"{publisher.resolved_name}")

    teleop = Teleop(params.speed, params.turn, idle_limit_for(params.key_timeout))
    fd = sys.stdin.fileno()
    try:
        with raw_mode(fd):
            _run(teleop, publisher, fd)
    except (KeyboardInterrupt, EOFError):
        pass
    finally:
        # The diff drive keeps its last command for ever: leave it a zero one.
        if not rospy.is_shutdown():
            publisher.publish(Twist())
        rospy.signal_shutdown('teleop finished')
    return 0
