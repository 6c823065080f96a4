"""One run, in a process of its own: ``python3 -m mbot_batch.run RUN.json FOLDER [--parent PID] [--gui] [--rviz]``.

It starts a private ROS master on a free port, sets the run's ROS parameters, then either the launch file (in
lockstep, with the run's seed) and the Python scenario that drives it, or ``rostest`` against that master. Every
process of the run has ROS_HOME, ROS_LOG_DIR and TMPDIR in FOLDER. roslaunch starts each node in a session of its
own, so neither a process group nor a session holds a run: this process is the run's subreaper, so that every
process of the run, an orphan too, is its descendant, and each carries the run's token in its environment
(``MBOT_BATCH_RUN``) unless it cleared it, for those found from outside when this process is gone. At the
timeout, on SIGINT/SIGTERM, when the process that started this one dies (a worker killed), and at the end, the
run is killed at once (``kill_token``). What it saw goes to FOLDER/raw.json; the logs to FOLDER/logs/.
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time

from .results import METRIC_LINE, parse_metrics
from .spec import Run

TOKEN_VARIABLE = "MBOT_BATCH_RUN"
POLL_SECONDS = 0.05
PR_SET_CHILD_SUBREAPER = 36  # linux/prctl.h
# What each log of a run's process keeps of its output (the driver gets all of it: 200 kB a log at most).
LOG_HEAD_BYTES = LOG_TAIL_BYTES = 100_000
# A longer line is not read for a metric (a scenario's metric lines are short).
METRIC_LINE_BYTES = 4096


def processes_with_token(prefix: str, exclude=()) -> list:
    """Pids whose environment holds a run token starting with ``prefix``."""
    wanted = f"{TOKEN_VARIABLE}={prefix}".encode()
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) in exclude:
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as stream:
                if any(variable.startswith(wanted) for variable in stream.read().split(b"\0")):
                    found.append(int(entry))
        except OSError:
            continue  # gone, or not ours to read
    return found


def kill_token(prefix: str, caller: int = None, rounds: int = 50) -> int:
    """SIGKILL every process of the runs whose tokens start with ``prefix``: each one holding a token in its
    environment and every descendant of one, so also a child started with a clean environment (``env -i``). A run
    process is its run's subreaper (``become_subreaper``): an orphan of the run, double-forked or not, stays its
    descendant while it lives. So the holders are stopped first (SIGSTOP: none starts a process or lets an orphan
    go to init meanwhile), their descendants are killed until none is left, the holders last. ``caller``, a run
    process killing its own run, is spared, and its descendants go too. Returns how many were killed."""
    holders = set(processes_with_token(prefix, exclude=(caller,)))
    _signal_all(holders, signal.SIGSTOP)
    roots = holders | ({caller} if caller else set())
    killed = set()
    for _ in range(rounds):
        below = _descendants(roots) - holders
        if not below:
            break
        killed |= _signal_all(below, signal.SIGKILL)
        time.sleep(0.01)
    return len(killed | _signal_all(holders, signal.SIGKILL))


def _signal_all(pids, number) -> set:
    """The pids that took the signal."""
    took = set()
    for pid in pids:
        try:
            os.kill(pid, number)
            took.add(pid)
        except (ProcessLookupError, PermissionError):
            pass
    return took


def _descendants(roots) -> set:
    """The live descendants of ``roots`` (not zombies: those are dead, waiting for their parent to reap them)."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as stream:
                    state, parent = stream.read().rsplit(")", 1)[1].split()[:2]
            except OSError:
                continue  # gone
            if state != "Z":
                children.setdefault(int(parent), []).append(int(entry))
    found, frontier = set(), list(roots)
    while frontier:
        for child in children.get(frontier.pop(), ()):
            if child not in found:
                found.add(child)
                frontier.append(child)
    return found


def become_subreaper():
    """Linux's PR_SET_CHILD_SUBREAPER: an orphaned descendant of this process (its parent died, a daemon's double
    fork) is reparented to this process rather than to init, so the run's every process stays a descendant of its
    run process whatever its environment, session or process group."""
    import ctypes
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
        print(f"mbot_batch.run: not the run's subreaper ({os.strerror(ctypes.get_errno())}): an orphan without the "
              f"run's token could outlive it", file=sys.stderr)


def _process_name(pid: int) -> str:
    """A ROS node's name (``__name:=``), a Python script's or module's name, or the program's."""
    with open(f"/proc/{pid}/cmdline", "rb") as stream:
        argv = [part.decode(errors="replace") for part in stream.read().split(b"\0") if part]
    for part in argv:
        if part.startswith("__name:="):
            return part.split("=", 1)[1]
    program = os.path.basename(argv[0]) if argv else str(pid)
    if program.startswith("python") and len(argv) > 1:
        script = next((part for part in argv[1:] if not part.startswith("-")), program)
        return argv[argv.index("-m") + 1] if "-m" in argv else os.path.basename(script)
    return program


def cpu_seconds(root: int) -> dict:
    """User and system CPU seconds of each live descendant of ``root`` (a run process: its run's subreaper), with
    the children it has waited for (roslaunch's: its xacro and spawn_model), by process name (summed over equal
    names)."""
    ticks = os.sysconf("SC_CLK_TCK")
    seconds = {}
    for pid in _descendants([root]):
        try:
            with open(f"/proc/{pid}/stat") as stream:
                fields = stream.read().rsplit(")", 1)[1].split()
            name = _process_name(pid)
        except OSError:
            continue  # ended meanwhile
        used = sum(int(field) for field in fields[11:15]) / ticks  # utime, stime, cutime, cstime
        seconds[name] = seconds.get(name, 0.0) + used
    return seconds


def left_out(count: int) -> bytes:
    return (f"\n[mbot batch: {count} bytes of output left out here; a log keeps its first {LOG_HEAD_BYTES} and "
            f"last {LOG_TAIL_BYTES} bytes]\n").encode()


def read_capped(path: str) -> bytes:
    """A log file as a ``CappedLog`` keeps it (a node's own ROS log, written by the node, may be longer)."""
    size = os.path.getsize(path)
    with open(path, "rb") as stream:
        if size <= LOG_HEAD_BYTES + LOG_TAIL_BYTES + len(left_out(sys.maxsize)):  # as a CappedLog keeps it
            return stream.read()
        head = stream.read(LOG_HEAD_BYTES)
        stream.seek(size - LOG_TAIL_BYTES)
        return head + left_out(size - LOG_HEAD_BYTES - LOG_TAIL_BYTES) + stream.read()


class CappedLog:
    """A process's output from the pipe ``read`` into ``path``, read by a thread of its own: its first
    LOG_HEAD_BYTES, a line saying how many bytes were left out, and its last LOG_TAIL_BYTES (a scenario printing
    200 MB had filled its run's folder as much). Every metric line is kept as it passes, wherever it was, for
    ``metric_lines``."""

    def __init__(self, path: str, read: int):
        self.stream = open(path, "wb")
        self.head_left = LOG_HEAD_BYTES
        self.tail = bytearray()
        self.dropped = 0
        self.partial = b""
        self.in_long_line = False
        self.metrics = {}  # name -> its last metric line
        self.thread = threading.Thread(target=self._pump, args=(read,), name=f"log {os.path.basename(path)}",
                                       daemon=True)
        self.thread.start()

    def _pump(self, read: int):
        with os.fdopen(read, "rb", buffering=0) as pipe:
            while chunk := pipe.read(1 << 16):
                head = chunk[:self.head_left]
                self.stream.write(head)
                self.head_left -= len(head)
                self.tail += chunk[len(head):]
                if len(self.tail) > LOG_TAIL_BYTES:
                    self.dropped += len(self.tail) - LOG_TAIL_BYTES
                    del self.tail[:-LOG_TAIL_BYTES]
                self._read_metrics(chunk)
        self._read_metrics(b"\n")  # a last line without its newline

    def _read_metrics(self, chunk: bytes):
        lines = (self.partial + chunk).split(b"\n")
        self.partial = lines.pop()
        for line in lines:
            if self.in_long_line:  # the end of a line too long to be a metric's
                self.in_long_line = False
            elif b"metric " in line:
                for match in METRIC_LINE.finditer(line.decode(errors="replace")):
                    self.metrics[match.group(1)] = match.group(0)
        if len(self.partial) > METRIC_LINE_BYTES:
            self.partial, self.in_long_line = b"", True

    def close(self, timeout: float = 5.0):
        """After the writers are gone (the pipe's end), or ``timeout`` seconds."""
        self.thread.join(timeout)
        if self.dropped:
            self.stream.write(left_out(self.dropped))
        self.stream.write(self.tail)
        self.stream.close()

    def metric_lines(self) -> str:
        return "\n".join(self.metrics.values())


class RunProcesses:
    def __init__(self, run: Run, folder: str, gui: bool, rviz: bool):
        self.run = run
        self.folder = folder
        self.gui, self.rviz = gui, rviz
        self.logs = os.path.join(folder, "logs")
        os.makedirs(self.logs, exist_ok=True)
        home = os.path.join(folder, "ros_home")
        temporary = os.path.join(folder, "tmp")
        os.makedirs(temporary, exist_ok=True)
        os.environ.update(ROS_HOME=home, ROS_LOG_DIR=os.path.join(home, "log"), TMPDIR=temporary,
                          PYTHONUNBUFFERED="1")
        self.captured = {}

    def start(self, command, log_name, environment=None):
        """The process, its output (stdout and stderr) captured into logs/LOG_NAME by a ``CappedLog``."""
        read, write = os.pipe()
        try:
            process = subprocess.Popen(command, stdout=write, stderr=subprocess.STDOUT, env=environment or os.environ)
        finally:
            os.close(write)
        self.captured[log_name] = CappedLog(os.path.join(self.logs, log_name), read)
        return process

    def close_logs(self):
        """Once every process of the run is gone: each log's tail written after its head."""
        for log in self.captured.values():
            log.close()

    def launch_arguments(self):
        arguments = dict(self.run.launch_args, lockstep="true", seed=str(self.run.seed))
        if self.gui:
            arguments["gui"] = "true"
        return [f"{name}:={value}" for name, value in arguments.items()]

    def execute(self, deadline: float, token: str) -> dict:
        from mbot_sim_bridge.processes import PrivateMaster
        raw = {"timeout": self.run.timeout, "timed_out": False, "error": None, "exit_code": None, "metrics": {}}
        master = PrivateMaster(timeout=max(1.0, deadline - time.monotonic()))
        os.environ["ROS_MASTER_URI"] = master.uri
        # roslaunch's own start-up (seconds under load) overlaps the master's: it waits for the master. Not when
        # the run sets parameters: those must be on the master before any node reads them.
        launch = None if self.run.rostest_path or self.run.ros_params else self.start_launch()
        with master:
            try:
                self.set_parameters()
                main_log, main, companions = self.start_run(launch or (self.run.launch_path and self.start_launch()))
                ended = self.wait(main, companions, deadline)
                raw["cpu_seconds"] = self.cpu_by_process(main_log)
            finally:
                # The metrics are out: the run's processes are killed at once rather than stopped in turn, which
                # took seconds per run under load. Its master too, then reaped by PrivateMaster.
                kill_token(token, caller=os.getpid())
            if ended == "timeout":
                raw["timed_out"] = True
            elif ended == "companion":
                raw["error"] = f"the launch ended (status {companions[0].returncode}) before the scenario"
            elif ended == "done":
                raw["exit_code"] = main.returncode
        self.close_logs()
        raw["metrics"] = parse_metrics(self.captured[main_log].metric_lines())
        if self.run.rostest_path and ended == "done":
            raw["rostest"] = self.rostest_counts()
        return raw

    @staticmethod
    def cpu_by_process(main_log: str) -> dict:
        """Where the run's CPU went, by process: this process, the main one (waited for, so in this one's
        children's times) and every other process of the run, still running."""
        own = os.times()
        return {**cpu_seconds(os.getpid()), "mbot_batch.run": own.user + own.system,
                os.path.splitext(main_log)[0]: own.children_user + own.children_system}

    def start_launch(self):
        return self.start(["roslaunch", "--wait", self.run.launch_path, *self.launch_arguments()], "launch.log")

    def start_run(self, launch):
        """The run's processes: rostest, or the launch file's (``launch``) scenario (and rviz); (main log, main
        process, companions whose end before the main one's is an error)."""
        environment = dict(os.environ, MBOT_BATCH_PARAMETERS=json.dumps(self.run.scenario_params))
        if self.run.rostest_path:
            main = self.start(["rostest", "--reuse-master", "--text", self.run.rostest_path,
                               *self.launch_arguments()], "rostest.log", environment)
            return "rostest.log", main, []
        main = self.start([sys.executable, self.run.python_path], "scenario.log", environment)
        companions = [launch]
        if self.rviz:
            companions.append(self.start(["rosrun", "rviz", "rviz", "-d", _rviz_config()], "rviz.log"))
        return "scenario.log", main, companions

    def set_parameters(self):
        import uuid

        import rosgraph
        master = rosgraph.Master("/mbot_batch")
        # As roscore sets it; roslaunch --wait waits for it.
        master.setParam("/run_id", str(uuid.uuid1()))
        for name, value in self.run.ros_params.items():
            master.setParam(name, value)

    @staticmethod
    def wait(main, companions, deadline) -> str:
        while True:
            if main.poll() is not None:
                return "done"
            if time.monotonic() > deadline:
                return "timeout"
            if companions and companions[0].poll() is not None:
                return "companion"
            time.sleep(POLL_SECONDS)

    def rostest_counts(self) -> dict:
        """rostest's summary lines: in --text mode (which puts the test nodes' metric lines on its output) it
        writes no XML results."""
        with open(os.path.join(self.logs, "rostest.log"), errors="replace") as stream:
            text = stream.read()
        counts = {name: re.findall(rf"\* {name}: (\d+)", text) for name in ("TESTS", "ERRORS", "FAILURES")}
        if not counts["TESTS"]:
            return {"tests": 0, "failed": 0}
        return {"tests": int(counts["TESTS"][-1]),
                "failed": int(counts["ERRORS"][-1]) + int(counts["FAILURES"][-1])}


def _rviz_config() -> str:
    import rospkg
    return os.path.join(rospkg.RosPack().get_path("mbot_description"), "config", "mbot_with_laser.rviz")


def end_with_parent_or_signal(token: str, parent: int, folder: str):
    """Kill the run and end this process at once on SIGINT/SIGTERM or when ``parent``, the process that started
    it, dies (a worker killed, a driver gone), whatever this process is doing: starting the master, waiting,
    stopping. The parent's pid comes from the parent: one that died while this process was still importing
    would otherwise go unnoticed. Without its parent, nobody will read the run's folder: it goes too.

    The end is always the signal handler's, in the main thread, the one that starts the run's processes: a watch
    thread that killed them itself could miss one the main thread started after its last scan (an orphaned
    master and launch were seen so)."""
    parent_gone = threading.Event()

    def end(*_):
        kill_token(token, caller=os.getpid())
        if parent_gone.is_set():
            shutil.rmtree(folder, ignore_errors=True)
        os._exit(1)

    def watch():
        while os.getppid() == parent:
            time.sleep(POLL_SECONDS)
        parent_gone.set()
        os.kill(os.getpid(), signal.SIGTERM)
    signal.signal(signal.SIGINT, end)
    signal.signal(signal.SIGTERM, end)
    threading.Thread(target=watch, name="parent watch", daemon=True).start()


def schedule_as_batch():
    """Linux's SCHED_BATCH for this process and, inherited, every process of the run. A run is a chain of processes
    handing each step on (scenario, simulator, its writer) beside nodes working off the chain: robot_state_publisher
    (whose roscpp timer thread wakes every millisecond under sim time) and the master answering its tf_prefix
    look-ups. With two runs on two cores, their wake-ups preempted the other run's simulator (perf sched: twice its
    context switches per run), and 2 workers gave 1.44x one; batch tasks wait for the running task's slice instead.
    No privilege needed; the results do not depend on it (lockstep)."""
    try:
        os.sched_setscheduler(0, os.SCHED_BATCH, os.sched_param(0))
    except (AttributeError, OSError) as error:  # not Linux, or a kernel without it: the runs only share cores worse
        print(f"mbot_batch.run: runs under the default scheduling policy (SCHED_BATCH: {error})", file=sys.stderr)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m mbot_batch.run", description=__doc__.splitlines()[0])
    parser.add_argument("run_file")
    parser.add_argument("folder")
    parser.add_argument("--gui", action="store_true")
    parser.add_argument("--rviz", action="store_true")
    parser.add_argument("--parent", type=int, help="the starting process's pid (default: the parent now)")
    args = parser.parse_args(argv)
    started = time.monotonic()
    token = os.environ.get(TOKEN_VARIABLE)
    if not token:
        print(f"mbot_batch.run: {TOKEN_VARIABLE} is not set", file=sys.stderr)
        return 2
    become_subreaper()
    end_with_parent_or_signal(token, args.parent or os.getppid(), args.folder)
    if not (args.gui or args.rviz):  # a rerun with a window is interactive
        schedule_as_batch()
    with open(args.run_file) as stream:
        run = Run.from_dict(json.load(stream))
    processes = RunProcesses(run, args.folder, args.gui, args.rviz)
    try:
        raw = processes.execute(started + run.timeout, token)
    except (RuntimeError, OSError) as error:
        raw = {"timeout": run.timeout, "timed_out": False, "error": f"the run could not start: {error}",
               "metrics": {}}
    finally:
        kill_token(token, caller=os.getpid())  # also when the start failed half-way
    raw["wall_seconds"] = time.monotonic() - started
    with open(os.path.join(args.folder, "raw.json.tmp"), "w") as stream:
        json.dump(raw, stream)
    os.replace(os.path.join(args.folder, "raw.json.tmp"), os.path.join(args.folder, "raw.json"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
