"""Processes, for every package of the workspace: a private master on a free port, a clean stop of a launched
process group and waiting on a condition (the demo, the benchmarks, the tests), a process's own stop request on
SIGINT/SIGTERM (the simulator node, ``./mbot sim``, the spawner and the unspawner), and for the nodes on the way
to the first /odom, rospy's init_node without its slow poll and a start-up without garbage collection."""
import gc
import os
import signal
import socket
import subprocess
import threading
import time

import rosgraph


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def wait_until(condition, timeout: float, what: str = None, interval: float = 0.02):
    """Poll ``condition`` every ``interval`` wall seconds until it returns a truthy value, which is returned; after
    ``timeout`` seconds an AssertionError naming ``what``, or None when ``what`` is None (the caller decides)."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            if what is None:
                return None
            raise AssertionError(f"timed out after {timeout:g} s waiting for {what}")
        time.sleep(interval)


def ignores_signal(pid: int, signum: int) -> bool:
    """Whether process ``pid`` ignores ``signum`` (its SigIgn mask in /proc; False when it cannot be read)."""
    try:
        with open(f"/proc/{pid}/status") as status:
            mask = next(int(line.split()[1], 16) for line in status if line.startswith("SigIgn:"))
    except (OSError, StopIteration, ValueError, IndexError):
        return False
    return bool(mask >> (signum - 1) & 1)


def stop_process_group(process: subprocess.Popen, timeout: float = 20.0) -> bool:
    """SIGINT the process's group (started with start_new_session=True), as Ctrl-C would; SIGKILL if it hangs.

    A process that ignores SIGINT gets SIGTERM instead: started from a script's background job (``cmd &``),
    this process and every child it starts inherit an ignored SIGINT, and rosmaster would wait out the timeout.
    False when it had to be killed (it ignored the signal for ``timeout`` seconds)."""
    if process.poll() is not None:
        return True
    os.killpg(process.pid, signal.SIGTERM if ignores_signal(process.pid, signal.SIGINT) else signal.SIGINT)
    try:
        process.wait(timeout=timeout)
        return True
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        return False


class PrivateMaster:
    """``with PrivateMaster() as master:`` a rosmaster on a free port; ``master.uri`` and ``master.environment``
    (this process's environment with ROS_MASTER_URI pointing at it) for the commands to run against it."""

    def __init__(self, timeout: float = 30.0):
        self.uri = f"http://127.0.0.1:{free_port()}"
        self.environment = dict(os.environ, ROS_MASTER_URI=self.uri)
        self.timeout = timeout
        self._process = None

    def __enter__(self):
        port = self.uri.rsplit(":", 1)[1]
        self._process = subprocess.Popen(["rosmaster", "--core", "-p", port], env=self.environment,
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        deadline = time.monotonic() + self.timeout
        while not rosgraph.is_master_online(master_uri=self.uri):
            if time.monotonic() > deadline or self._process.poll() is not None:
                self.__exit__()
                raise RuntimeError(f"no ROS master came up at {self.uri} within {self.timeout:.0f} s")
            time.sleep(0.05)
        return self

    def __exit__(self, *exc_info):
        stop_process_group(self._process)


def stop_on_signals() -> threading.Event:
    """An Event that SIGINT and SIGTERM set, for a main thread that stops itself cleanly, outside any lock.

    Python runs a signal handler in the main thread, and it may run while that thread is inside the same Event's
    ``wait`` holding the Event's lock: ``Event.set`` there waits for that lock for ever (an unspawner hung so in
    the suite). The handler therefore leaves the ``set`` to a short-lived thread of its own.
    """
    stop = threading.Event()

    def request_stop(*_):
        threading.Thread(target=stop.set, name="stop request", daemon=True).start()

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, request_stop)
    return stop


class _CappedSleeps:
    """The time module as ``init_node`` below shows it to rospy.impl.init: sleeps of at most 1 ms."""

    def __getattr__(self, name):
        return getattr(time, name)

    @staticmethod
    def sleep(seconds: float):
        time.sleep(min(seconds, 0.001))


def init_node(name: str, **options):
    """rospy.init_node with its wait for the master's registration polled every 1 ms: rospy/impl/init.py sleeps
    0.1 s between checks, so about every other start waited up to 0.1 s after the node was registered."""
    import rospy
    import rospy.impl.init as rospy_init
    rospy_init.time = _CappedSleeps()
    try:
        rospy.init_node(name, **options)
    finally:
        rospy_init.time = time


def end_start_up():
    """Garbage collection back on after a start-up without it (the server's and spawn_model's scripts switch it
    off before their first import), with the start-up's objects frozen. Those imports and the world make
    hundreds of thousands of objects that live as long as the process; each full collection among them scanned
    them all, about 20 ms of the simulator's start-up. Frozen, they are never scanned again."""
    gc.freeze()
    gc.enable()
