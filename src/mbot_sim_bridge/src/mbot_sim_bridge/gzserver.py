"""gazebo_ros's server executables (gzserver, gazebo, debug, perf, gdbrun, gzclient) for the PyBullet bridge.

``gzserver`` takes gzserver's command line, resolves the world as Gazebo does (a file, else relative to
GAZEBO_RESOURCE_PATH, the packages' gazebo_media_path exports and the workspace, which holds
``worlds/empty.world``) and runs the bridge's node with it. ``gazebo`` is the same with the window open,
``debug`` runs it under pdb, ``perf`` under cProfile. ``gzclient`` and ``gdbrun`` exit with one line saying
what to use instead. Options that have no meaning for the bridge warn once and are ignored; options whose
absence would make the run wrong (log playback, a fixed iteration count) are refused.
"""
import argparse
import json
import os
import sys

import rospkg
import rospy

from .core.description.model_path import find_world_file
from .gazebo_paths import prefetch_package_exports, resource_path

# gazebo_ros's system plugins: the bridge is both of them.
BUILT_IN_SYSTEM_PLUGINS = ("libgazebo_ros_paths_plugin.so", "libgazebo_ros_api_plugin.so")
DEFAULT_WORLD = "worlds/empty.world"


class CommandLineError(Exception):
    pass


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=prog, description="gzserver's command line, run by the PyBullet bridge "
                                     "(node 'gazebo', gazebo_ros's topics and services).")
    parser.add_argument("world", nargs="?", default=DEFAULT_WORLD,
                        help="SDF world: a file, or relative to GAZEBO_RESOURCE_PATH, the gazebo_media_path exports "
                             "and gazebo_ros (default %(default)s)")
    parser.add_argument("-u", "--pause", action="store_true", help="start with physics paused")
    parser.add_argument("-e", "--physics", default="ode", help="accepted; the engine is always Bullet")
    parser.add_argument("--verbose", action="store_true", help="log the bridge at DEBUG")
    parser.add_argument("--seed", type=int, help="seed of the sensor noise")
    parser.add_argument("-s", "--server-plugin", action="append", default=[], metavar="PLUGIN",
                        help="system plugin; gazebo_ros's paths and API plugins are built in")
    parser.add_argument("-g", "--gui-plugin", action="append", default=[], metavar="PLUGIN",
                        help="GUI plugin: not emulated (warns)")
    parser.add_argument("-r", "--record", action="store_true", help="not supported: warns, runs without recording")
    for option in ("--record_path", "--record_period", "--record_filter", "--record_encoding"):
        parser.add_argument(option, help="not supported: warns")
    parser.add_argument("-p", "--play", metavar="LOG", help="refused: the bridge plays no Gazebo logs")
    parser.add_argument("--iters", type=int, help="refused: the bridge runs until stopped")
    parser.add_argument("-o", "--profile", help="Gazebo physics profile: not supported (warns)")
    for flag in ("-q", "--quiet", "--minimal_comms", "--lockstep"):
        parser.add_argument(flag, action="store_true", help="accepted (the bridge always steps in lockstep)")
    return parser


def bridge_arguments(prog: str, argv, gui: bool = None):
    """The bridge node's argv for a gzserver command line: ROS remappings kept, private params added.

    ``argv`` is the full command line (sys.argv); remappings (``a:=b``, ``__name:=``) pass through untouched.
    """
    remappings = [argument for argument in argv[1:] if ":=" in argument]
    options = _parser(prog).parse_args(rospy.myargv(argv)[1:])
    if options.play:
        raise CommandLineError(f"-p/--play {options.play}: the bridge does not play Gazebo logs")
    if options.iters is not None:
        raise CommandLineError(f"--iters {options.iters}: the bridge runs until stopped (use rosservice call "
                               "/gazebo/pause_physics to stop the physics)")
    for plugin in options.server_plugin:
        if os.path.basename(plugin) not in BUILT_IN_SYSTEM_PLUGINS:
            _note(prog, f"system plugin {plugin} is not emulated; ignored")
    for plugin in options.gui_plugin:
        _note(prog, f"GUI plugin {plugin} is not emulated; ignored")
    if options.record or options.record_path or options.record_period or options.record_filter \
            or options.record_encoding:
        _note(prog, "recording (-r, --record_*) is not supported; running without recording")
    if options.profile:
        _note(prog, f"physics profile {options.profile} is not supported; the world's <physics> is used")
    if options.physics != "ode":
        _note(prog, f"-e {options.physics}: the bridge's engine is always Bullet")
    # An absolute path goes to the bridge as it is: a missing or bad file is the bridge's one fatal line. Only a
    # relative one needs the resource path (a rospack run, which can take a while when its cache is cold).
    world = options.world
    if not os.path.isabs(world):
        search_path = resource_path()
        world = find_world_file(options.world, search_path)
        if world is None:
            raise CommandLineError(f"world file {options.world} not found here nor on the resource "
                                   f"path {':'.join(search_path)}")
    # Private params set on the command line override the launch file's and any left on the master by an
    # earlier run; values are JSON, which rospy reads as YAML.
    params = {"world_name": world, "paused": options.pause}
    if options.seed is not None:
        params["seed"] = options.seed
    if gui is not None:
        params["gui"] = gui
    arguments = [argv[0]] + remappings + [f"_{name}:={json.dumps(value)}" for name, value in params.items()]
    return arguments + (["--verbose"] if options.verbose else [])


def _note(prog: str, message: str):
    print(f"{prog}: {message}", file=sys.stderr, flush=True)


def _run(prog: str, runner, gui: bool = None):
    try:
        sys.argv = bridge_arguments(prog, sys.argv, gui)
    except CommandLineError as error:
        print(f"{prog}: {error}", file=sys.stderr)
        sys.exit(1)
    # The node reads the model path (a rospack run) once imported: rospack runs meanwhile.
    prefetch_package_exports("gazebo_model_path")
    # Imported here, so that a refused command line and gzclient answer without loading PyBullet.
    from .node import main
    runner(main)


def gzserver():
    _run("gzserver", lambda main: main())


def gazebo():
    """gzserver and gzclient in one: the bridge with its window."""
    _run("gazebo", lambda main: main(), gui=True)


def debug():
    """The server under pdb (gazebo_ros runs gzserver under gdb)."""
    import pdb  # here, not at the top: every launch imports this module, and pdb costs 15 ms of it

    _run("debug", pdb.Pdb().runcall)


def perf():
    """The server under cProfile (gazebo_ros runs gzserver under valgrind's callgrind)."""
    import cProfile
    path = os.path.join(rospkg.get_ros_home(), "gzserver.prof")

    def profile(main):
        profiler = cProfile.Profile()
        try:
            profiler.runcall(main)
        finally:
            profiler.dump_stats(path)
            _note("perf", f"profile written to {path} (read it with: python3 -m pstats {path})")
    _run("perf", profile)


def gzclient():
    print("gzclient: the bridge has no separate client; its window opens with the server "
          "(empty_world.launch gui:=true, or rosrun gazebo_ros gazebo); to watch a running simulation use rviz",
          file=sys.stderr)
    sys.exit(1)


def gdbrun():
    print("gdbrun: the bridge is Python; use rosrun gazebo_ros debug (pdb) or empty_world.launch debug:=true",
          file=sys.stderr)
    sys.exit(1)
