"""The real mbot_teleop.py on a pseudo-terminal: keys in, Twists out on cmd_vel.

The module starts its own ROS master on a free port and stops every process it
starts. Each teleop gets its own node name and cmd_vel topic (by remapping), so
tests cannot see each other's parameters or messages. The test process itself
stays out of the ROS graph: `rostopic echo` children record the Twists.
"""

import itertools
import os
import signal
import subprocess
import sys
import termios
import tty
from xmlrpc.client import ServerProxy

import pytest
import rosgraph

from mbot_sim_bridge.processes import PrivateMaster
from teleop_harness import PACKAGE_DIR, PtyProcess, TwistRecorder, source_env, teleop_command, wait_until

pytestmark = pytest.mark.long

NOT_A_TERMINAL = ('mbot_teleop: stdin is not a terminal; run it from a terminal: '
                  'rosrun mbot_teleop mbot_teleop.py')
START_TIMEOUT = 30.0  # s: a cold start of rospy on a busy machine
STEP_TIMEOUT = 10.0  # s
RAW_FLAGS = termios.ICANON | termios.ECHO | termios.ISIG
# The course's grid, written out again so the test does not trust the package's table.
MOVES = {'u': (1, 1), 'i': (1, 0), 'o': (1, -1), 'j': (0, 1),
         'l': (0, -1), 'm': (-1, -1), ',': (-1, 0), '.': (-1, 1)}
STOP = (0.0, 0.0)

_ids = itertools.count(1)


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.fixture(scope='module')
def ros_env(tmp_path_factory):
    """Start a private master; yield the environment for the processes that use it."""
    with PrivateMaster(timeout=START_TIMEOUT) as master:
        yield dict(source_env(master.environment), ROS_HOSTNAME='localhost',
                   ROS_HOME=str(tmp_path_factory.mktemp('ros_home')))


@pytest.fixture
def start_teleop(ros_env):
    """Factory: start a teleop on a pty with extra ROS arguments; return (process, recorder)."""
    started = []

    def start(*ros_args, wait_ready=True):
        """wait_ready=False: a teleop expected to exit at once, whose commands nobody records (recorder None)."""
        n = next(_ids)
        topic = f'/pty_test_{n}/cmd_vel'
        recorder = TwistRecorder(topic, ros_env) if wait_ready else None
        command = teleop_command(f'__name:=mbot_teleop_{n}', f'cmd_vel:={topic}', *ros_args)
        teleop = PtyProcess(command, ros_env)
        started.append((teleop, recorder))
        # It publishes every cycle: a first message means it polls keys and we are connected.
        if wait_ready:
            assert wait_until(lambda: len(recorder), START_TIMEOUT), teleop.output
        return teleop, recorder

    yield start
    for teleop, recorder in started:
        teleop.close()
        if recorder is not None:
            recorder.close()


@pytest.fixture(scope='module')
def module_teleop(ros_env):
    """One teleop with the default parameters for the tests that leave it at rest at the default speeds (no
    speed key, no exit): a teleop's start-up is most of such a test's CPU."""
    topic = '/pty_test_shared/cmd_vel'
    recorder = TwistRecorder(topic, ros_env)
    teleop = PtyProcess(teleop_command('__name:=mbot_teleop_shared', f'cmd_vel:={topic}'), ros_env)
    try:
        assert wait_until(lambda: len(recorder), START_TIMEOUT), teleop.output
        yield teleop, recorder
    finally:
        teleop.close()
        recorder.close()


@pytest.fixture
def default_teleop(module_teleop):
    """The module's default teleop, stopped (space) before the test whatever ran before it."""
    teleop, recorder = module_teleop
    start = len(recorder)
    teleop.send(' ')
    assert wait_until(lambda: recorder.commands(start)[-1:] == [STOP], STEP_TIMEOUT), recorder.commands(start)
    return module_teleop


def drive(teleop, recorder, keys, count):
    """Type keys in one write; return count commands, from the first non-zero one they cause.

    The keys sit in the terminal together, so the teleop spends one cycle on each
    without idle polls in between: the sequence is deterministic.
    """
    start = len(recorder)
    teleop.send(keys)

    def caused():
        commands = list(itertools.dropwhile(lambda c: c == STOP, recorder.commands(start)))
        return commands[:count] if len(commands) >= count else None

    commands = wait_until(caused, STEP_TIMEOUT)
    assert commands, f'fewer than {count} commands after {keys!r}: {recorder.commands(start)}'
    return commands


def assert_commands(got, expected):
    assert len(got) == len(expected)
    assert [value for pair in got for value in pair] == pytest.approx(
        [value for pair in expected for value in pair], abs=1e-9), got


def ramp(first, last, step, direction=1):
    """Commands n * step for n = first..last (either way), scaled by direction."""
    sign = 1 if last >= first else -1
    return [n * step * direction for n in range(first, last + sign, sign)]


def test_starts_raw_prints_help_speeds_and_params(default_teleop):
    teleop, recorder = default_teleop
    assert not teleop.mode()[tty.LFLAG] & RAW_FLAGS
    assert teleop.wait_for_output('currently:\tspeed 0.2\tturn 1.0', STEP_TIMEOUT), teleop.output
    assert 'Control mbot!' in teleop.output
    assert 'space key, k : force stop' in teleop.output
    assert ('speed 0.2 m/s (default), turn 1 rad/s (default), key_timeout 0.5 s, '
            f'publishing on {recorder.topic}') in teleop.output


def test_move_keys_ramp_toward_their_direction(default_teleop):
    teleop, recorder = default_teleop
    for key, (x, th) in MOVES.items():
        got = drive(teleop, recorder, key * 10 + ' ', 11)
        expected = list(zip(ramp(1, 10, 0.02, x), ramp(1, 10, 0.1, th))) + [STOP]
        assert_commands(got, expected)
    assert all(fields[1:5] == (0, 0, 0, 0) for fields in recorder.messages)


def test_stop_keys_stop_at_once(default_teleop):
    teleop, recorder = default_teleop
    for stop_key in ' k':
        got = drive(teleop, recorder, 'u' * 5 + stop_key, 6)
        assert_commands(got, list(zip(ramp(1, 5, 0.02), ramp(1, 5, 0.1))) + [STOP])


def test_idle_stop_ramps_down_after_five_idle_polls(default_teleop):
    teleop, recorder = default_teleop
    # No key after the ramp: four idle polls keep the target, the fifth drops it to zero.
    got = drive(teleop, recorder, 'i' * 10, 24)
    linear = ramp(1, 10, 0.02) + [0.2] * 4 + ramp(9, 0, 0.02)
    assert_commands(got, [(v, 0.0) for v in linear])
    # Keys without a binding count as idle polls.
    got = drive(teleop, recorder, 'j' * 10 + 'a' * 5, 24)
    angular = ramp(1, 10, 0.1) + [1.0] * 4 + ramp(9, 0, 0.1)
    assert_commands(got, [(0.0, w) for w in angular])


def test_speed_keys_rescale_and_print_the_speeds(start_teleop):
    teleop, recorder = start_teleop()
    got = drive(teleop, recorder, 'q' + 'i' * 11 + ' ', 12)
    assert_commands(got, [(v, 0.0) for v in ramp(1, 11, 0.02)] + [STOP])
    assert teleop.wait_for_output('currently:\tspeed 0.22\tturn 1.1', STEP_TIMEOUT)
    for key, speeds in [('z', '0.198\tturn 0.99'), ('w', '0.2178\tturn 0.99'),
                        ('x', '0.196\tturn 0.99'), ('e', '0.196\tturn 1.089'),
                        ('c', '0.196\tturn 0.9801')]:
        teleop.send(key)
        assert teleop.wait_for_output('currently:\tspeed ' + speeds, STEP_TIMEOUT), teleop.output
    # As in the course, the help comes back with every 15th speed line.
    assert teleop.output.count('Control mbot!') == 1
    teleop.send('ec' * 4 + 'e')
    assert teleop.wait_for_output('Control mbot!', STEP_TIMEOUT, count=2)


@pytest.mark.parametrize('ending', ['ctrl-c', 'SIGINT', 'SIGTERM', 'SIGHUP'])
def test_exit_publishes_zero_twist_and_restores_the_terminal(start_teleop, ending):
    # Without the idle stop only the exit can bring the command back to zero.
    teleop, recorder = start_teleop('_key_timeout:=0')
    drive(teleop, recorder, 'i' * 10, 10)
    moving = len(recorder)
    if ending == 'ctrl-c':
        teleop.send('\x03')
    else:
        teleop.proc.send_signal(getattr(signal, ending))
    assert teleop.proc.wait(timeout=STEP_TIMEOUT) == 0
    assert wait_until(lambda: recorder.commands(moving)[-1:] == [STOP], STEP_TIMEOUT)
    # From the last command before the ending: full speed until the one zero Twist.
    tail = recorder.commands(moving - 1)
    assert_commands(tail, [(0.2, 0.0)] * (len(tail) - 1) + [STOP])
    assert teleop.mode() == teleop.initial_mode
    assert 'Traceback' not in teleop.output


@pytest.mark.parametrize('ros_args, speed, turn, log', [
    ((), 0.2, 1.0, 'speed 0.2 m/s (default), turn 1 rad/s (default)'),
    (('_scale_linear:=0.1', '_scale_angular:=0.4'), 0.1, 0.4,
     'speed 0.1 m/s (~scale_linear), turn 0.4 rad/s (~scale_angular)'),
    (('_speed:=0.3', '_turn:=0.5', '_scale_linear:=0.1', '_scale_angular:=0.4'), 0.3, 0.5,
     'speed 0.3 m/s (~speed), turn 0.5 rad/s (~turn)'),
], ids=['defaults', 'course-params', 'speed-beats-scale'])
def test_speed_params_set_the_starting_speeds(request, start_teleop, ros_args, speed, turn, log):
    teleop, recorder = start_teleop(*ros_args) if ros_args else request.getfixturevalue('default_teleop')
    assert teleop.wait_for_output(log, STEP_TIMEOUT), teleop.output
    assert teleop.wait_for_output(f'currently:\tspeed {speed}\tturn {turn}', STEP_TIMEOUT)
    if '_speed:=0.3' in ros_args:
        assert '~speed is set, so ~scale_linear is ignored' in teleop.output
    # Ten cycles of 'u' reach at least the smaller targets; the last command shows the plateau.
    got = drive(teleop, recorder, 'u' * 10 + ' ', 11)
    assert got[-2] == pytest.approx((min(speed, 0.2), min(turn, 1.0))), got


@pytest.mark.parametrize('ros_arg, message', [
    ('_speed:=-1', '~speed must be a number > 0, got -1'),
    ('_scale_angular:=fast', "~scale_angular must be a number > 0, got 'fast'"),
    ('_key_timeout:=-0.5', '~key_timeout must be a number >= 0, got -0.5'),
])
def test_bad_param_is_fatal(start_teleop, ros_arg, message):
    teleop, _ = start_teleop(ros_arg, wait_ready=False)
    assert teleop.proc.wait(timeout=START_TIMEOUT) == 1
    assert teleop.wait_for_output(message, STEP_TIMEOUT), teleop.output
    assert teleop.mode() == teleop.initial_mode


@pytest.mark.parametrize('stdin', [{'input': b'iii'}, {'stdin': subprocess.DEVNULL}],
                         ids=['piped', 'devnull'])
def test_without_a_terminal_exits_1_with_one_line(stdin):
    env = source_env()
    env['ROS_MASTER_URI'] = 'http://localhost:9/'  # nothing listens: ROS must not be reached
    result = subprocess.run(teleop_command(), env=env, capture_output=True, timeout=STEP_TIMEOUT,
                            **stdin)
    assert result.returncode == 1
    assert result.stderr.decode() == NOT_A_TERMINAL + '\n'
    assert result.stdout == b''


def test_ctrl_c_while_waiting_for_the_master_exits_quietly(tmp_path):
    env = source_env()
    env.update(ROS_MASTER_URI='http://localhost:9/', ROS_HOME=str(tmp_path))  # no master there
    teleop = PtyProcess(teleop_command(), env)
    try:
        assert teleop.wait_for_output('Unable to register', START_TIMEOUT), teleop.output
        teleop.proc.send_signal(signal.SIGINT)
        assert teleop.proc.wait(timeout=STEP_TIMEOUT) == 1
        assert 'Traceback' not in teleop.output
        assert teleop.mode() == teleop.initial_mode
    finally:
        teleop.close()


def test_launch_file_gives_the_node_the_terminal_and_course_speeds(ros_env):
    env = dict(ros_env, ROS_PACKAGE_PATH=PACKAGE_DIR)
    # The script's "#!/usr/bin/env python3" must find a Python that has rospy.
    env['PATH'] = os.pathsep.join([os.path.dirname(sys.executable), env['PATH']])
    recorder = TwistRecorder('/cmd_vel', env)
    launch = PtyProcess(['roslaunch', 'mbot_teleop', 'mbot_teleop.launch'], env)
    teleop_pid = None
    try:
        speeds = 'currently:\tspeed 0.1\tturn 0.4'
        assert launch.wait_for_output(speeds, START_TIMEOUT), launch.output
        assert wait_until(lambda: len(recorder), START_TIMEOUT)
        master = rosgraph.Master('/teleop_pty_test', master_uri=env['ROS_MASTER_URI'])
        teleop_pid = ServerProxy(master.lookupNode('/mbot_teleop')).getPid('/teleop_pty_test')[2]
        got = drive(launch, recorder, 'i' * 6 + ' ', 7)
        assert_commands(got, [(v, 0.0) for v in ramp(1, 5, 0.02)] + [(0.1, 0.0), STOP])
        # The teleop was the launch's only node, so roslaunch ends with it.
        launch.send('\x03')
        assert launch.proc.wait(timeout=STEP_TIMEOUT) == 0
        assert launch.wait_for_output('process has finished cleanly', STEP_TIMEOUT)
        assert launch.mode() == launch.initial_mode
    finally:
        launch.close()
        recorder.close()
        # roslaunch gives each node a session of its own, so make sure the node went with it.
        if teleop_pid is not None and wait_until(lambda: not _alive(teleop_pid), 10) is None:
            os.kill(teleop_pid, signal.SIGKILL)
