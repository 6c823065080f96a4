"""``rosrun controller_manager controller_manager COMMAND [NAME ...]``: upstream's commands and abbreviations."""
import sys

import rospy

from . import controller_manager_interface as interface

USAGE = """Commands:
    load <name>          - Load the controller named <name>
    unload <name>        - Unload the controller named <name>
    start <name>         - Start the controller named <name>
    stop <name>          - Stop the controller named <name>
    spawn <name>         - Load and start the controller named <name>
    kill <name>          - Stop and unload the controller named <name>
    list                 - List active controllers
    list-types           - List controller Types
    reload-libraries     - Reloads all plugin controller libraries"""


def _each(function, names):
    return all([function(name) for name in names])


def main():
    args = rospy.myargv()
    if len(args) < 2:
        print(USAGE)
        sys.exit(0)
    command, names = args[1], args[2:]
    commands = {
        "lt": interface.list_controller_types, "list-types": interface.list_controller_types,
        "lc": interface.list_controllers, "list": interface.list_controllers,
        "reload-libraries": lambda: interface.reload_libraries(True, restore="--restore" in names),
        "load": lambda: _each(interface.load_controller, names),
        "unload": lambda: _each(interface.unload_controller, names),
        "start": lambda: _each(interface.start_controller, names),
        "stop": lambda: _each(interface.stop_controller, names),
        "sp": lambda: _each(interface.load_controller, names) and _each(interface.start_controller, names),
        "kl": lambda: _each(interface.stop_controller, names) and _each(interface.unload_controller, names),
    }
    commands["spawn"], commands["kill"] = commands["sp"], commands["kl"]
    if command not in commands:
        print(USAGE)
        sys.exit(1)
    rospy.init_node("controller_manager", anonymous=True)
    try:
        result = commands[command]()
    except rospy.ROSInterruptException:
        return
    sys.exit(0 if result is not False else 1)
