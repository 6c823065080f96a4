"""``./mbot sim``'s roslaunch: a launch file run as ``roslaunch PACKAGE FILE name:=value...`` would, except that
it ends when the simulator (the node named ``gazebo``) stops, with the simulator's exit status.

That is gazebo_ros's ``server_required:=true`` for the workspace's own launch files, without changing them:
a bad world or robot stops the whole launch with the simulator's one-line error and a non-zero status,
instead of leaving robot_state_publisher and the spawner running on.
"""
import os
import sys
import threading
import time

import roslaunch
import roslaunch.arg_dump
import roslaunch.parent
import roslaunch.pmon
import roslaunch.rlutil
from mbot_sim_bridge.processes import stop_on_signals

SERVER_NODE = "gazebo"


class ServerWatch(roslaunch.pmon.ProcessListener):
    """Remembers the simulator's exit status when its process dies."""

    def __init__(self):
        self.exit_code = None
        self.died = threading.Event()

    def process_died(self, process_name, exit_code):
        # roslaunch names a node's process NAME-N.
        if process_name.rsplit("-", 1)[0] == SERVER_NODE:
            self.exit_code = exit_code
            self.died.set()


def arguments_help(launch_file: str, declared: dict) -> str:
    """The arguments a launch file lets the command line set (those with a default), with their docs."""
    lines = [f"{launch_file} takes:"]
    for name, (doc, default) in declared.items():
        shown = default if default else "''"
        lines.append(f"  {name}:={shown}" + (f"    {doc}" if doc else ""))
    return "\n".join(lines)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 2:
        print("usage: mbot_sim_launch PACKAGE FILE.launch [name:=value ... | --help]", file=sys.stderr)
        return 2
    package, launch_file, launch_args = argv[0], argv[1], argv[2:]
    try:
        path = roslaunch.rlutil.resolve_launch_arguments([package, launch_file])[0]
        declared = roslaunch.arg_dump.get_args([path])
    except roslaunch.RLException as error:
        print(f"mbot sim: {error}", file=sys.stderr)
        return 1
    if launch_args == ["--help"]:
        try:
            print(arguments_help(launch_file, declared), flush=True)
        except BrokenPipeError:  # `| head` has read what it wanted; Python's exit would complain on the flush
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    # roslaunch ignores an argument the file does not declare: a typo or a wrong world would pass unnoticed.
    unknown = [name for name in (argument.split(":=", 1)[0] for argument in launch_args) if name not in declared]
    if unknown:
        print(f"mbot sim: {launch_file} has no argument '{unknown[0]}'; it takes {', '.join(declared)} "
              "(./mbot sim --help WORLD says what each does)", file=sys.stderr)
        return 2
    run_id = roslaunch.rlutil.get_or_generate_uuid(None, False)
    roslaunch.configure_logging(run_id)
    watch = ServerWatch()
    parent = roslaunch.parent.ROSLaunchParent(run_id, [(path, launch_args)], process_listeners=[watch])
    # Ctrl-C and kill end the launch as they end roslaunch.
    stop = stop_on_signals()
    try:
        parent.start()
        # A simulator that died before the listener was registered is already in the dead list.
        for process in list(parent.pm.dead_list):
            watch.process_died(process.name, process.exit_code)
        while not (stop.is_set() or watch.died.is_set()) and parent.pm.is_alive():
            parent.spin_once()
            time.sleep(0.1)
    except roslaunch.RLException as error:
        print(f"mbot sim: {error}", file=sys.stderr)
        return 1
    finally:
        parent.shutdown()
    if watch.died.is_set() and not stop.is_set():
        print(f"mbot sim: the simulator stopped (exit status {watch.exit_code}); the launch is shut down",
              file=sys.stderr)
        return watch.exit_code if watch.exit_code else 1
    return 0
