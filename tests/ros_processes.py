"""Helpers for the tests that run ROS command lines (a module, not conftest.py, so tests can import it)."""
import functools
import os
import subprocess

from mbot_sim_bridge.processes import wait_until  # noqa: F401 (the tests take it from here with the others)

TESTS = os.path.dirname(os.path.abspath(__file__))


def run(command, environment, timeout=90, stdin=None):
    """Run a ROS command line to completion; returns the CompletedProcess (text output)."""
    return subprocess.run(command, env=environment, capture_output=True, text=True, timeout=timeout, stdin=stdin)


@functools.lru_cache(maxsize=None)
def node_executable(package, executable):
    """The file ``rosrun PACKAGE EXECUTABLE`` runs, found as roslaunch finds a node's type. Run directly, it skips
    rosrun's own start (a shell script calling catkin_find and rospack: 0.4 CPU seconds a call)."""
    import roslib.packages

    found = roslib.packages.find_node(package, executable)
    assert found, f"no executable {executable} in package {package}"
    return found[0]


def rosrun(package, executable, *arguments):
    """The command line of ``rosrun PACKAGE EXECUTABLE ARGUMENTS...`` without rosrun's start (node_executable)."""
    return [node_executable(package, executable), *arguments]


def service_up(environment, service):
    """Whether the master knows ``service`` (asked from this process, as ``rosservice list`` would)."""
    import rosgraph

    try:
        rosgraph.Master("/test", master_uri=environment["ROS_MASTER_URI"]).lookupService(service)
        return True
    except (rosgraph.MasterError, OSError):
        return False


def call_service(environment, service, request="{}", timeout=60):
    """What ``rosservice call SERVICE REQUEST`` prints, parsed, but called from this process: a service client
    needs no node, and a ``rosservice`` process costs a second or more of interpreter start on a loaded machine.
    Raises rospy.ServiceException as the command would fail."""
    import genpy
    import rospy
    import rosservice
    import yaml

    # rosgraph reads the master's address from the environment at every lookup.
    saved = os.environ.get("ROS_MASTER_URI")
    os.environ["ROS_MASTER_URI"] = environment["ROS_MASTER_URI"]
    try:
        rospy.wait_for_service(service, timeout)
        service_class = rosservice.get_service_class_by_name(service)
        message = service_class._request_class()
        genpy.message.fill_message_args(message, [yaml.safe_load(request)])
        response = rospy.ServiceProxy(service, service_class)(message)
    finally:
        if saved is None:
            del os.environ["ROS_MASTER_URI"]
        else:
            os.environ["ROS_MASTER_URI"] = saved
    return yaml.safe_load(genpy.message.strify_message(response))


def processes_named(marker):
    """Live processes whose command line has ``marker`` as one of its words (found without their environment)."""
    found = []
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/cmdline", "rb") as stream:
                named = marker.encode() in stream.read().split(b"\0")
            with open(f"/proc/{entry}/stat") as stream:
                alive = stream.read().rsplit(")", 1)[1].split()[0] != "Z"
        except (OSError, IndexError):
            continue  # not a process, or gone
        if named and alive:
            found.append(int(entry))
    return found


def folder_bytes(folder):
    """Every file under ``folder``, by its path relative to it, with its bytes."""
    files = {}
    for root, _, names in os.walk(folder):
        for name in names:
            with open(os.path.join(root, name), "rb") as stream:
                files[os.path.relpath(os.path.join(root, name), folder)] = stream.read()
    return files
