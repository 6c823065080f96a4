"""Python helpers around the controller manager services, with the names and output of ros_control's module.

Service names are relative (``controller_manager/...``), so they resolve in the caller's namespace, as
upstream's do; ``rosrun controller_manager controller_manager list __ns:=/robot`` reaches /robot's manager.
"""
import rospy
from controller_manager_msgs.srv import (ListControllers, ListControllersRequest, ListControllerTypes,
                                         ListControllerTypesRequest, LoadController, LoadControllerRequest,
                                         ReloadControllerLibraries, ReloadControllerLibrariesRequest,
                                         SwitchController, SwitchControllerRequest, UnloadController,
                                         UnloadControllerRequest)

_PREFIX = "controller_manager/"


def _service(name, service_type):
    rospy.wait_for_service(_PREFIX + name)
    return rospy.ServiceProxy(_PREFIX + name, service_type)


def list_controller_types():
    for controller_type in _service("list_controller_types", ListControllerTypes)(ListControllerTypesRequest()).types:
        print(controller_type)


def list_controllers():
    controllers = _service("list_controllers", ListControllers)(ListControllersRequest()).controller
    if not controllers:
        print("No controllers are loaded in mechanism control")
    for state in controllers:
        interfaces = sorted(set(resource.hardware_interface for resource in state.claimed_resources))
        print(f"'{state.name}' - '{'+'.join(interfaces)}' ( {state.state} )")


def load_controller(name):
    ok = _service("load_controller", LoadController)(LoadControllerRequest(name)).ok
    print(f"Loaded '{name}'" if ok else f"Error when loading '{name}'")
    return ok


def unload_controller(name):
    ok = _service("unload_controller", UnloadController)(UnloadControllerRequest(name)).ok
    print(f"Unloaded '{name}' successfully" if ok else f"Error when unloading '{name}'")
    return ok


def start_stop_controllers(start_controllers=(), stop_controllers=()):
    request = SwitchControllerRequest(list(start_controllers), list(stop_controllers),
                                      SwitchControllerRequest.STRICT, False, 0.0)
    ok = _service("switch_controller", SwitchController)(request).ok
    if ok:
        if start_controllers:
            print(f"Started {list(start_controllers)} successfully")
        if stop_controllers:
            print(f"Stopped {list(stop_controllers)} successfully")
    else:
        print(f"Error when starting {list(start_controllers)} and stopping {list(stop_controllers)}")
    return ok


def start_controller(name):
    return start_stop_controllers(start_controllers=[name])


def start_controllers(names):
    return start_stop_controllers(start_controllers=names)


def stop_controller(name):
    return start_stop_controllers(stop_controllers=[name])


def stop_controllers(names):
    return start_stop_controllers(stop_controllers=names)


def reload_libraries(force_kill, restore=False):
    reload_service = _service("reload_controller_libraries", ReloadControllerLibraries)
    print("Restore: " + str(restore))
    before = _service("list_controllers", ListControllers)(ListControllersRequest()).controller if restore else []
    ok = reload_service(ReloadControllerLibrariesRequest(force_kill)).ok
    print("Successfully reloaded libraries" if ok
          else "Failed to reload libraries. Do you still have controllers loaded?")
    if restore:
        load = _service("load_controller", LoadController)
        for state in before:
            load(state.name)
        _service("switch_controller", SwitchController)(
            start_controllers=[state.name for state in before if state.state == "running"], stop_controllers=[],
            strictness=SwitchControllerRequest.BEST_EFFORT)
        print("Controllers restored to original state")
    return ok
