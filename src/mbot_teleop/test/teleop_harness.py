"""Drives the real teleop script through a pseudo-terminal; shared by the pty and drive tests."""

import os
import select
import subprocess
import sys
import termios
import threading
import time

from mbot_sim_bridge.processes import stop_process_group, wait_until  # noqa: F401 (the tests take it from here)

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TELEOP_SCRIPT = os.path.join(PACKAGE_DIR, 'scripts', 'mbot_teleop.py')


def teleop_command(*ros_args):
    """The teleop under this Python, with ROS command-line arguments (remaps, _params)."""
    return [sys.executable, TELEOP_SCRIPT, *ros_args]


def source_env(env=None):
    """env with the package importable from its source tree, built or not."""
    env = dict(os.environ if env is None else env)
    src = os.path.join(PACKAGE_DIR, 'src')
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [src, env.get('PYTHONPATH')]))
    return env


class PtyProcess:
    """A process started with a fresh pseudo-terminal as stdin, stdout and stderr.

    The test holds the master side: send() types keys, output collects what the
    process prints, and mode() reads the terminal's current termios mode.
    """

    def __init__(self, argv, env):
        self._master, self._slave = os.openpty()
        self.initial_mode = termios.tcgetattr(self._slave)
        self._output = bytearray()
        self._changed = threading.Condition()
        self._closing = threading.Event()
        # A session of its own, as roslaunch gives its nodes: the pty is not its controlling tty.
        self.proc = subprocess.Popen(argv, stdin=self._slave, stdout=self._slave,
                                     stderr=self._slave, env=env, start_new_session=True)
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()

    def _drain(self):
        # Keep reading: once the pty buffer fills, the process would block on print().
        while not self._closing.is_set():
            ready, _, _ = select.select([self._master], [], [], 0.05)
            if not ready:
                continue
            try:
                data = os.read(self._master, 4096)
            except OSError:
                return
            with self._changed:
                self._output += data
                self._changed.notify_all()

    @property
    def output(self):
        with self._changed:
            return self._output.decode(errors='replace')

    def wait_for_output(self, text, timeout, count=1):
        """Wait until text has appeared count times in the output; return whether it did."""
        deadline = time.monotonic() + timeout
        needle = text.encode()
        with self._changed:
            while self._output.count(needle) < count:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._changed.wait(remaining)
        return True

    def send(self, keys):
        os.write(self._master, keys.encode('latin-1'))

    def mode(self):
        return termios.tcgetattr(self._slave)

    def close(self):
        """Stop the process if it still runs and release the pty."""
        stop_process_group(self.proc)
        self._closing.set()
        self._reader.join(timeout=5)
        os.close(self._master)
        os.close(self._slave)


class TwistRecorder:
    """Every Twist on a topic, in order, as seen by a `rostopic echo -p` child process.

    A child process keeps the test process free of a rospy node, which can be
    initialised only once per process.
    """

    def __init__(self, topic, env):
        self.topic = topic
        self.messages = []  # (linear.x, .y, .z, angular.x, .y, .z)
        self._lock = threading.Lock()
        self._echo = subprocess.Popen(['rostopic', 'echo', '-p', topic],
                                      env=dict(env, PYTHONUNBUFFERED='1'), stdout=subprocess.PIPE,
                                      stderr=subprocess.DEVNULL, text=True, start_new_session=True)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self._echo.stdout:
            if line.startswith('%'):  # the CSV header
                continue
            fields = tuple(float(field) for field in line.split(',')[1:])
            with self._lock:
                self.messages.append(fields)

    def commands(self, start=0):
        """(linear.x, angular.z) of the messages from index start on."""
        with self._lock:
            return [(fields[0], fields[5]) for fields in self.messages[start:]]

    def __len__(self):
        with self._lock:
            return len(self.messages)

    def close(self):
        stop_process_group(self._echo)
        self._reader.join(timeout=5)
        self._echo.stdout.close()
