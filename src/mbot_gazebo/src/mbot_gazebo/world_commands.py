"""Building a world in the running simulator, as with Gazebo's Insert tab, its move tool and "Save world as".

``mbot_world models`` lists what can be inserted; ``insert``, ``move`` and ``delete`` arrange models through
the /gazebo services (insert is ``spawn_model -sdf -database NAME``, as gazebo_ros does); ``save-world``
calls the bridge's own /gazebo/save_world. Every failure is one line on stderr and exit status 1.
"""
import argparse
import os
import sys

import rospy
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import DeleteModel, GetModelState, GetWorldProperties, SetModelState
from mbot_sim_msgs.srv import SaveWorld

from mbot_gazebo.model_library import UnknownModel, find_model, format_table, instance_name, list_models

SERVICE_TIMEOUT = 15.0  # seconds to wait for the simulator's services


class CommandError(Exception):
    pass


def parse_arguments(argv):
    parser = argparse.ArgumentParser(prog="mbot_world", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("models", help="list the models that can be inserted: name, description, path")
    insert = commands.add_parser("insert", help="insert model NAME (spawn_model -sdf -database NAME)")
    insert.add_argument("name", metavar="NAME")
    move = commands.add_parser("move", help="move model INSTANCE (set_model_state); unset values are kept")
    move.add_argument("instance", metavar="INSTANCE")
    for command, default in ((insert, 0.0), (move, None)):
        for axis in ("x", "y", "z", "Y"):
            command.add_argument("-" + axis, type=float, default=default,
                                 help=f"{'yaw' if axis == 'Y' else axis} ({'rad' if axis == 'Y' else 'm'})")
    insert.add_argument("--as", dest="instance", metavar="INSTANCE",
                        help="name in the simulator (default: NAME, then NAME_0, NAME_1... as Gazebo names them)")
    delete = commands.add_parser("delete", help="delete model INSTANCE")
    delete.add_argument("instance", metavar="INSTANCE")
    save = commands.add_parser("save-world", help="write the running world as an SDF 1.6 file")
    save.add_argument("path", metavar="OUT.world")
    save.add_argument("--with-robots", action="store_true",
                      help="also write the robots spawned from URDF (as inline models, plugins kept as tags)")
    return parser.parse_args(argv)


def _proxy(name, service_type):
    try:
        rospy.wait_for_service(name, timeout=SERVICE_TIMEOUT)
    except rospy.ROSException:
        raise CommandError(f"no simulator answers on {name} (start one with ./mbot sim WORLD)") from None
    return rospy.ServiceProxy(name, service_type)


def _model_names():
    return list(_proxy("/gazebo/get_world_properties", GetWorldProperties)().model_names)


def insert(arguments):
    model = find_model(arguments.name, list_models())
    existing = _model_names()  # also waits for the simulator, which spawn_model would do for ever
    instance = arguments.instance or instance_name(model.name, existing)
    from mbot_sim_bridge import spawn_model  # here, not above: PyBullet's import prints to stdout
    spawn_arguments = spawn_model.parse_arguments(
        ["-sdf", "-database", model.name, "-model", instance, "-x", repr(arguments.x), "-y", repr(arguments.y),
         "-z", repr(arguments.z), "-Y", repr(arguments.Y)])
    try:
        spawn_model.spawn(spawn_arguments)
    except spawn_model.SpawnError as error:
        raise CommandError(str(error)) from None
    print(f"inserted {model.name} as '{instance}' at x {arguments.x:g} y {arguments.y:g} z "
          f"{arguments.z:g} yaw {arguments.Y:g}")


def move(arguments):
    from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, rpy  # here: PyBullet's import prints
    current = _proxy("/gazebo/get_model_state", GetModelState)(arguments.instance, "")
    if not current.success:
        raise CommandError(f"cannot move '{arguments.instance}': {current.status_message}")
    position = current.pose.position
    q = current.pose.orientation
    roll, pitch, yaw = rpy((q.x, q.y, q.z, q.w))
    requested = (arguments.x, arguments.y, arguments.z)
    xyz = tuple(old if new is None else new for old, new in zip((position.x, position.y, position.z), requested))
    pose = pose_from_xyz_rpy(xyz, (roll, pitch, yaw if arguments.Y is None else arguments.Y))
    state = ModelState(model_name=arguments.instance, reference_frame="")
    state.pose.position.x, state.pose.position.y, state.pose.position.z = pose.position
    (state.pose.orientation.x, state.pose.orientation.y, state.pose.orientation.z,
     state.pose.orientation.w) = pose.orientation
    result = _proxy("/gazebo/set_model_state", SetModelState)(state)
    if not result.success:
        raise CommandError(f"cannot move '{arguments.instance}': {result.status_message}")
    x, y, z = xyz
    print(f"moved '{arguments.instance}' to x {x:g} y {y:g} z {z:g} yaw {rpy(pose.orientation)[2]:g}")


def delete(arguments):
    result = _proxy("/gazebo/delete_model", DeleteModel)(arguments.instance)
    if not result.success:
        raise CommandError(f"cannot delete '{arguments.instance}': {result.status_message}")
    print(f"deleted '{arguments.instance}'")


def save_world(arguments):
    result = _proxy("/gazebo/save_world", SaveWorld)(os.path.abspath(arguments.path), arguments.with_robots)
    if not result.success:
        raise CommandError(f"save-world failed: {result.status_message}")
    print(result.status_message)


COMMANDS = {"insert": insert, "move": move, "delete": delete, "save-world": save_world}


def main(argv=None):
    arguments = parse_arguments(sys.argv[1:] if argv is None else argv)
    try:
        if arguments.command == "models":
            print(format_table(list_models()))
            return
        rospy.init_node("mbot_world", anonymous=True, disable_signals=True)
        COMMANDS[arguments.command](arguments)
    except (CommandError, UnknownModel, rospy.ServiceException, rospy.ROSException) as error:
        print(f"mbot_world: {error}", file=sys.stderr)
        sys.exit(1)
