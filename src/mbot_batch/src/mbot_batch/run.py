"""One run, in a process of its own: ``python3 -m mbot_batch.run RUN.json FOLDER [--parent PID] [--gui] [--rviz]``.

It starts a private ROS master on a free port, sets the run's ROS parameters, then either the launch file (in
lockstep, with the run's seed) and the Python scenario that drives it, or ``rostest`` against that master. Every
process of the run has ROS_HOME, ROS_LOG_DIR and TMPDIR in FOLDER, and carries the run's token in its environment
(``MBOT_BATCH_RUN``): roslaunch starts each node in a session of its own, so a process group does not hold a run,
and the token finds every process of it, even one whose parent died. At the timeout, on SIGINT/SIGTERM, when
the process that started this one dies (a worker killed), and at the end, every process with the token is
killed at once. What it saw goes to FOLDER/raw.json; the logs to FOLDER/logs/.
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

from .results import parse_metrics
from .spec import Run

TOKEN_VARIABLE = "MBOT_BATCH_RUN"
POLL_SECONDS = 0.05


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


def kill_token(prefix: str, exclude=(), rounds: int = 50) -> int:
    """SIGKILL every process whose token starts with ``prefix``, again until none is left (one may have started
    a child meanwhile); returns how many were killed."""
    killed = set()
    for _ in range(rounds):
        pids = [pid for pid in processes_with_token(prefix, exclude) if pid not in killed or _alive(pid)]
        if not pids:
            break
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
                killed.add(pid)
            except ProcessLookupError:
                pass
        time.sleep(0.01)
    return len(killed)


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


def cpu_seconds(prefix: str, exclude=()) -> dict:
    """User and system CPU seconds of each live process with a token starting with ``prefix``, with the children
    it has waited for (roslaunch's: its xacro and spawn_model), by process name (summed over equal names)."""
    ticks = os.sysconf("SC_CLK_TCK")
    seconds = {}
    for pid in processes_with_token(prefix, exclude):
        try:
            with open(f"/proc/{pid}/stat") as stream:
                fields = stream.read().rsplit(")", 1)[1].split()
            name = _process_name(pid)
        except OSError:
            continue  # ended meanwhile
        used = sum(int(field) for field in fields[11:15]) / ticks  # utime, stime, cutime, cstime
        seconds[name] = seconds.get(name, 0.0) + used
    return seconds


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as stream:
            return stream.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


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

    def log(self, name: str):
        return open(os.path.join(self.logs, name), "w")

    def start(self, command, log_name, environment=None):
        with self.log(log_name) as log:
            return subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=environment or os.environ)

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
                raw["cpu_seconds"] = self.cpu_by_process(token, main_log)
            finally:
                # The metrics are out: the run's processes are killed at once rather than stopped in turn, which
                # took seconds per run under load. Its master too, then reaped by PrivateMaster.
                kill_token(token, exclude=(os.getpid(),))
            if ended == "timeout":
                raw["timed_out"] = True
            elif ended == "companion":
                raw["error"] = f"the launch ended (status {companions[0].returncode}) before the scenario"
            elif ended == "done":
                raw["exit_code"] = main.returncode
        with open(os.path.join(self.logs, main_log), errors="replace") as stream:
            raw["metrics"] = parse_metrics(stream.read())
        if self.run.rostest_path and ended == "done":
            raw["rostest"] = self.rostest_counts()
        return raw

    @staticmethod
    def cpu_by_process(token: str, main_log: str) -> dict:
        """Where the run's CPU went, by process: this process, the main one (waited for, so in this one's
        children's times) and every other process of the run, still running."""
        own = os.times()
        return {**cpu_seconds(token, exclude=(os.getpid(),)), "mbot_batch.run": own.user + own.system,
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
        kill_token(token, exclude=(os.getpid(),))
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
        kill_token(token, exclude=(os.getpid(),))  # also when the start failed half-way
    raw["wall_seconds"] = time.monotonic() - started
    with open(os.path.join(args.folder, "raw.json.tmp"), "w") as stream:
        json.dump(raw, stream)
    os.replace(os.path.join(args.folder, "raw.json.tmp"), os.path.join(args.folder, "raw.json"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
