"""gazebo_ros's ``spawn_model`` command line, talking to the bridge's /gazebo/spawn_*_model services.

Exits 1 with one line naming the problem (missing file or parameter, invalid XML, a refused spawn) where
gazebo_ros's script would print a traceback.
"""
import argparse
import sys
import time
from xml.etree import ElementTree

import rosgraph
import rospy
from gazebo_msgs.srv import DeleteModel, GetPhysicsProperties, SetModelConfiguration, SpawnModel
from geometry_msgs.msg import Pose
from std_srvs.srv import Empty

from .core.geometry import pose_from_xyz_rpy
from .processes import end_start_up, init_node

SERVICE_POLL_SECONDS = 0.02


class SpawnError(Exception):
    pass


class OneLineArgumentParser(argparse.ArgumentParser):
    """A bad command line is said in one line (argparse prints its whole usage first), with argparse's status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: {message} (spawn_model -h lists the options)\n")


def parse_arguments(argv):
    parser = OneLineArgumentParser(prog="spawn_model", description="Spawn a model in the simulator "
                                     "(gazebo_ros's spawn_model command line).")
    kind = parser.add_mutually_exclusive_group(required=True)
    kind.add_argument("-urdf", action="store_true", help="the model is URDF")
    kind.add_argument("-sdf", action="store_true", help="the model is SDF")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("-file", metavar="FILE", help="read the model from FILE")
    source.add_argument("-param", metavar="PARAM", help="read the model from ROS parameter PARAM")
    source.add_argument("-stdin", action="store_true", help="read the model from standard input")
    source.add_argument("-database", metavar="NAME", help="the model://NAME model (SDF)")
    parser.add_argument("-model", required=True, metavar="NAME", help="name of the model in the simulator")
    for axis in ("x", "y", "z", "R", "P", "Y"):
        parser.add_argument("-" + axis, type=float, default=0.0, help=f"initial {axis} (m or rad)")
    parser.add_argument("-J", nargs=2, action="append", metavar=("JOINT", "POSITION"), default=[],
                        help="set JOINT to POSITION (rad or m) before the model's first step; repeatable")
    parser.add_argument("-reference_frame", default="", help="pose relative to this model ('' = world)")
    parser.add_argument("-robot_namespace", default=None, help="namespace injected into the model's plugins "
                        "(default: this node's namespace)")
    parser.add_argument("-gazebo_namespace", default="/gazebo", help="namespace of the simulator's services")
    parser.add_argument("-timeout", type=float, default=None, metavar="SECONDS",
                        help="seconds to wait for the spawn and unpause services to appear (gazebo_ros 3's option; "
                             "default: wait for ever, as gazebo_ros 2's spawn_model does)")
    parser.add_argument("-unpause", action="store_true", help="unpause physics after spawning")
    parser.add_argument("-wait", metavar="MODEL", help="wait until MODEL exists before spawning")
    parser.add_argument("-package_to_model", action="store_true",
                        help="accepted for compatibility: the bridge resolves package:// URIs itself")
    parser.add_argument("-b", dest="bond", action="store_true", help="delete the model when this node stops")
    arguments = parser.parse_args(argv)
    if arguments.timeout is not None and not 0 < arguments.timeout < float("inf"):
        parser.error(f"-timeout must be a number of seconds > 0, got {arguments.timeout}")
    try:
        arguments.J = [(joint, float(position)) for joint, position in arguments.J]
    except ValueError as error:
        parser.error(f"-J takes a joint name and a position (a number): {error}")
    return arguments


def read_model_xml(arguments) -> str:
    if arguments.database:
        return (f"<sdf version='1.6'><world name='default'><include><uri>model://{arguments.database}</uri>"
                "</include></world></sdf>")
    if arguments.file:
        try:
            with open(arguments.file) as model_file:
                xml = model_file.read()
        except OSError as error:
            raise SpawnError(f"cannot read model file {arguments.file}: {error.strerror}") from None
        where = f"model file {arguments.file}"
    elif arguments.param:
        if not rospy.has_param(arguments.param):
            raise SpawnError(f"parameter {rospy.resolve_name(arguments.param)} is not set (load the "
                             "robot_description first)")
        xml = str(rospy.get_param(arguments.param))
        where = f"parameter {rospy.resolve_name(arguments.param)}"
    else:
        xml = sys.stdin.read()
        where = "standard input"
    if not xml.strip():
        raise SpawnError(f"{where} is empty")
    try:
        # Parsed and re-serialised as gazebo_ros does: drops the XML declaration and comments.
        return ElementTree.tostring(ElementTree.fromstring(xml), encoding="unicode")
    except ElementTree.ParseError as error:
        raise SpawnError(f"{where} is not valid XML: {error}") from None


def initial_pose(arguments) -> Pose:
    pose = pose_from_xyz_rpy((arguments.x, arguments.y, arguments.z), (arguments.R, arguments.P, arguments.Y))
    message = Pose()
    message.position.x, message.position.y, message.position.z = pose.position
    q = pose.orientation
    message.orientation.x, message.orientation.y, message.orientation.z, message.orientation.w = q
    return message


def wait_for_model(arguments):
    from gazebo_msgs.msg import ModelStates
    rospy.loginfo(f"waiting for model {arguments.wait}")
    while not rospy.is_shutdown():
        try:
            states = rospy.wait_for_message(arguments.gazebo_namespace + "/model_states", ModelStates, timeout=1.0)
        except rospy.ROSException:
            continue
        if arguments.wait in states.name:
            return


def wait_for_service(name: str, timeout):
    rospy.loginfo(f"waiting for service {name}")
    deadline = None if timeout is None else time.monotonic() + timeout
    master = rosgraph.Master(rospy.get_name())
    # rospy.wait_for_service polls every 0.3 s. spawn_model starts together with the simulator, so that poll
    # alone added 0.15 s on average to roslaunch-to-first-/odom; asking the master every 20 ms costs nothing.
    while not rospy.is_shutdown():
        remaining = None if deadline is None else deadline - time.monotonic()
        if remaining is not None and remaining <= 0:
            raise SpawnError(f"service {name} did not appear within {timeout:g} s (-timeout): is the simulator running "
                             "(roslaunch gazebo_ros empty_world.launch)?")
        try:
            master.lookupService(name)
        except (rosgraph.MasterError, OSError):  # not registered yet, or the master not up yet
            time.sleep(SERVICE_POLL_SECONDS)
            continue
        try:
            rospy.wait_for_service(name, remaining)  # registered: now the usual check that it answers
            return
        except rospy.ROSInterruptException:
            raise  # shut down while waiting (Ctrl-C): main() exits 1 without a message
        except rospy.ROSException:
            continue  # the deadline passed while it was being contacted: reported above
    raise rospy.ROSInterruptException("rospy shutdown")


def spawn(arguments):
    service_name = f"{arguments.gazebo_namespace}/spawn_{'urdf' if arguments.urdf else 'sdf'}_model"
    model_xml = read_model_xml(arguments)
    if arguments.wait:
        wait_for_model(arguments)
    wait_for_service(service_name, arguments.timeout)
    namespace = arguments.robot_namespace if arguments.robot_namespace is not None else rospy.get_namespace()
    # With -J the physics is held paused from the spawn to the joints' setting, so the model's first step starts
    # from them (gazebo_ros's spawn_model sets them afterwards, while the model may already be falling).
    resume = bool(arguments.J) and not physics_paused(arguments)
    if resume:
        call_empty(arguments, "pause_physics")
    try:
        response = rospy.ServiceProxy(service_name, SpawnModel)(arguments.model, model_xml, namespace,
                                                                initial_pose(arguments), arguments.reference_frame)
        if not response.success:
            raise SpawnError(f"spawning '{arguments.model}' failed: {response.status_message}")
        rospy.loginfo(f"spawned '{arguments.model}': {response.status_message}")
        if arguments.J:
            set_joints(arguments)
    finally:
        if resume:
            call_empty(arguments, "unpause_physics")
    if arguments.unpause:
        call_empty(arguments, "unpause_physics")


def physics_paused(arguments) -> bool:
    name = arguments.gazebo_namespace + "/get_physics_properties"
    wait_for_service(name, arguments.timeout)
    return rospy.ServiceProxy(name, GetPhysicsProperties)().pause


def call_empty(arguments, service: str):
    name = f"{arguments.gazebo_namespace}/{service}"
    wait_for_service(name, arguments.timeout)
    rospy.ServiceProxy(name, Empty)()


def set_joints(arguments):
    """-J through set_model_configuration; joints the model lacks are named in one line, and the rest set."""
    name = arguments.gazebo_namespace + "/set_model_configuration"
    wait_for_service(name, arguments.timeout)
    joints, positions = zip(*arguments.J)
    response = rospy.ServiceProxy(name, SetModelConfiguration)(arguments.model, "", joints, positions)
    if not response.success:
        raise SpawnError(f"'{arguments.model}' spawned, but -J was refused: {response.status_message}")
    if response.status_message != "SetModelConfiguration: success":
        print(f"spawn_model: -J: {response.status_message}", file=sys.stderr)


def main():
    arguments = parse_arguments(rospy.myargv(sys.argv)[1:])
    init_node("spawn_model", anonymous=True)
    end_start_up()
    try:
        spawn(arguments)
    except (SpawnError, rospy.ServiceException) as error:
        print(f"spawn_model: {error}", file=sys.stderr)
        sys.exit(1)
    except rospy.ROSInterruptException:
        sys.exit(1)
    if arguments.bond:
        def delete_model():
            try:
                rospy.ServiceProxy(arguments.gazebo_namespace + "/delete_model", DeleteModel)(arguments.model)
            except (rospy.ServiceException, rospy.ROSException) as error:
                print(f"spawn_model: could not delete '{arguments.model}' on exit: {error}", file=sys.stderr)
        rospy.on_shutdown(delete_model)
        rospy.spin()
