"""``libgazebo_ros_control.so``: the controller manager's services, the controllers' topics, the e-stop.

Services (under ``<robotNamespace>/controller_manager/``) run in rospy's threads and are serialized, as
upstream's; load and unload work there, a switch is performed by the next control update in the loop thread
and waited for (so it waits while the simulation is paused, as in Gazebo).
"""
import threading

import rospy
from controller_manager_msgs.msg import ControllerState, HardwareInterfaceResources
from controller_manager_msgs.srv import (ListControllers, ListControllersResponse, ListControllerTypes,
                                         ListControllerTypesResponse, LoadController, LoadControllerResponse,
                                         ReloadControllerLibraries, ReloadControllerLibrariesResponse,
                                         SwitchController, SwitchControllerResponse, UnloadController,
                                         UnloadControllerResponse)
from std_msgs.msg import Bool

from ..core.ros_control.gazebo_ros_control import GazeboRosControlPlugin
from . import RosPlugin, resolve_in_namespace, ros_time
from .ros_controllers import ROS_CONTROLLERS

_BASE_CLASS = "controller_interface::ControllerBase"


class GazeboRosControl(RosPlugin, GazeboRosControlPlugin):
    CONTROLLERS = ROS_CONTROLLERS

    def __init__(self, context, element, sensor=None):
        self._services_lock = threading.Lock()
        super().__init__(context, element, sensor)
        prefix = resolve_in_namespace(self.namespace, "controller_manager") + "/"
        if self.params["eStopTopic"]:
            self.topics.subscriber(resolve_in_namespace(self.namespace, self.params["eStopTopic"]), Bool,
                                   self._on_e_stop)
        handlers = (("list_controllers", ListControllers, self._list_controllers),
                    ("list_controller_types", ListControllerTypes, self._list_controller_types),
                    ("load_controller", LoadController, self._load_controller),
                    ("unload_controller", UnloadController, self._unload_controller),
                    ("switch_controller", SwitchController, self._switch_controller),
                    ("reload_controller_libraries", ReloadControllerLibraries, self._reload_libraries))
        for name, service_type, handler in handlers:
            self.topics.service(prefix + name, service_type, self._serialized(handler))
        joints = ", ".join(f"{name}: {joint.interface}" for name, joint in self.hw.joints.items())
        rospy.loginfo(f"{self.label}: controller manager in namespace {self.namespace}: {len(self.hw.joints)} joints "
                      f"({joints}), control period {self.control_period:.4f} s")

    # -- topics ------------------------------------------------------------------------------------------
    def _on_e_stop(self, message: Bool):
        self.e_stop = message.data

    def update(self, now):
        stamp = ros_time(now)
        for loaded in self.publish_now:
            loaded.controller.publish(stamp)
        super().update(now)

    # -- services ----------------------------------------------------------------------------------------
    def _serialized(self, handler):
        def serve(request):
            with self._services_lock:
                return handler(request)
        return serve

    def _list_controllers(self, request):
        states = []
        for loaded in self.manager.list():
            resources = [HardwareInterfaceResources(interface, list(names)) for interface, names in loaded.claimed]
            states.append(ControllerState(loaded.name, loaded.state, loaded.type, resources))
        return ListControllersResponse(states)

    def _list_controller_types(self, request):
        return ListControllerTypesResponse(self.manager.types, [_BASE_CLASS] * len(self.manager.types))

    def _load_controller(self, request):
        return LoadControllerResponse(self.load_controller(request.name))

    def _unload_controller(self, request):
        return UnloadControllerResponse(self.manager.unload(request.name))

    def _switch_controller(self, request):
        return SwitchControllerResponse(self._switch(request.start_controllers, request.stop_controllers,
                                                     request.strictness, request.start_asap, request.timeout))

    def _switch(self, start, stop, strictness, start_asap=False, timeout=0.0):
        return self.manager.switch(start, stop, strictness, start_asap, timeout, self._wait)

    @staticmethod
    def _wait(done: threading.Event, timeout: float) -> bool:
        """Upstream waits for the realtime loop for timeout + 1 s of wall time, or for ever when timeout is 0."""
        limit = timeout + 1.0 if timeout > 0 else None
        waited = 0.0
        while not done.wait(0.1):
            waited += 0.1
            if rospy.is_shutdown() or (limit is not None and waited >= limit):
                return False
        return True

    def _reload_libraries(self, request):
        names = [loaded.name for loaded in self.manager.list()]
        if names and not request.force_kill:
            rospy.logerr("Controller manager: Cannot reload controller libraries because there are still "
                         f"{len(names)} controllers running")
            return ReloadControllerLibrariesResponse(False)
        if names:
            rospy.loginfo("Controller manager: Killing all running controllers")
            if not self._switch([], names, 1):
                rospy.logerr("Controller manager: Cannot reload controller libraries because failed to stop running "
                             "controllers")
                return ReloadControllerLibrariesResponse(False)
            for name in names:
                if not self.manager.unload(name):
                    rospy.logerr("Controller manager: Cannot reload controller libraries because failed to "
                                 f"unload controller '{name}'")
                    return ReloadControllerLibrariesResponse(False)
        rospy.loginfo("Controller manager: reloaded controller libraries for 'controller_interface'")
        return ReloadControllerLibrariesResponse(True)
