"""controller_manager's load/unload/switch (with strictness and resource conflicts)/list, with upstream's log
texts. Services call it from ROS threads; ``update`` runs in the loop thread."""
import threading
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from ..log import get_logger
from .controller_interface import Controller, LoadContext
from .hardware_interface import INTERFACE_TYPES, HardwareInterfaceError
from .robot_hw_sim import DefaultRobotHWSim

_logger = get_logger(__name__)


class ControllerInitError(Exception):
    """A controller's init failed; the message lines are what upstream logs before 'Initializing ... failed'."""


class ControllerInitException(Exception):
    """What upstream's init throws (ros::Duration out of range): controller_manager logs it as a thrown exception."""


@dataclass
class LoadedController:
    name: str
    type: str
    controller: Controller
    claimed: List[Tuple[str, List[str]]]  # (hardware interface type, resources)

    @property
    def state(self) -> str:
        return self.controller.state


class ControllerManager:
    """controller_manager::ControllerManager over a DefaultRobotHWSim.

    ``factory(type)`` returns the controller class for a type string, or None; ``get_params(name)`` the
    controller's parameters as a dict (None when it has none). load/unload/switch/list are called from service
    threads; ``update`` from the loop thread. A switch is handed to the next ``update`` and waited for, as
    upstream's realtime switch is (so it waits while the simulation is paused).
    """

    def __init__(self, hw: DefaultRobotHWSim, factory: Callable[[str], Optional[type]], types: Sequence[str],
                 get_params: Callable[[str], Optional[dict]], namespace: str = "/",
                 clock: Callable[[], float] = lambda: 0.0):
        self.hw = hw
        self.clock = clock
        self.factory = factory
        self.types = list(types)
        self.get_params = get_params
        self.namespace = namespace
        self.controllers: List[LoadedController] = []  # replaced, never mutated: the loop reads it without lock
        # The update methods of the running controllers that have one, in load order: the loop's every-step work.
        self._updates: List[Callable[[float, float], None]] = []
        self._lock = threading.RLock()
        self._switch_request: Optional[Tuple[list, list, threading.Event]] = None
        self.closed = False  # unload_all ran: the model is gone, and a switch can no longer be carried out

    # -- service side ------------------------------------------------------------------------------------
    def find(self, name: str) -> Optional[LoadedController]:
        return next((loaded for loaded in self.controllers if loaded.name == name), None)

    def load(self, name: str, urdf=None) -> bool:
        with self._lock:
            if self.find(name) is not None:
                _logger.error(f"A controller named '{name}' was already loaded inside the controller manager")
                return False
            params = self.get_params(name)
            controller_type = params.get("type") if isinstance(params, dict) else None
            if not isinstance(controller_type, str):
                _logger.error(f"Could not load controller '{name}' because the type was not specified. Did you load "
                              "the controller configuration on the parameter server (namespace: "
                              f"'{_join(self.namespace, name)}')?")
                return False
            controller_class = self.factory(controller_type)
            if controller_class is None:
                _logger.error(f"Could not load controller '{name}' because controller type "
                              f"'{controller_type}' does not exist.")
                _logger.error("Use 'rosservice call controller_manager/list_controller_types' to get the available "
                              "types")
                return False
            context = LoadContext(urdf, _join(self.namespace, name), self.clock)
            try:
                controller = controller_class(name, self.hw, params, context)
            except ControllerInitError as error:
                for line in str(error).splitlines():
                    _logger.error(line)
                _logger.error("Failed to initialize the controller")
                _logger.error(f"Initializing controller '{name}' failed")
                return False
            except (HardwareInterfaceError, ControllerInitException) as error:
                _logger.error(f"Exception thrown while initializing controller '{name}'.\n{error}")
                _logger.error(f"Initializing controller '{name}' failed")
                return False
            claimed = ([(INTERFACE_TYPES[interface], list(joints)) for interface, joints in controller.claimed.items()]
                       or [(INTERFACE_TYPES[controller.INTERFACE], [])])
            self.controllers = self.controllers + [LoadedController(name, controller_type, controller, claimed)]
            _logger.debug(f"Successfully load controller '{name}'")
            return True

    def unload(self, name: str) -> bool:
        with self._lock:
            loaded = self.find(name)
            if loaded is None:
                _logger.error(f"Could not unload controller with name '{name}' because no "
                              "controller with this name exists")
                return False
            if loaded.state == "running":
                _logger.error(f"Could not unload controller with name '{name}' because it is still running")
                return False
            self.controllers = [other for other in self.controllers if other is not loaded]
            loaded.controller.close()
            return True

    def switch(self, start: Sequence[str], stop: Sequence[str], strictness: int, start_asap: bool = False,
               timeout: float = 0.0, wait: Optional[Callable[[threading.Event, float], bool]] = None) -> bool:
        """SwitchController: checks as upstream, then waits for the loop to do it. ``wait(event, timeout)``
        blocks until the event is set (returns False if it gave up)."""
        if strictness == 0:
            _logger.warning("Controller Manager: To switch controllers you need to specify a strictness level of "
                            "controller_manager_msgs::SwitchController::STRICT (2) or ::BEST_EFFORT (1). Defaulting "
                            "to ::BEST_EFFORT.")
            strictness = 1
        strict = strictness == 2
        with self._lock:
            stop_list, start_list = [], []
            for names, target, verb in ((stop, stop_list, "stop"), (start, start_list, "start")):
                for name in names:
                    loaded = self.find(name)
                    if loaded is None:
                        if strict:
                            _logger.error(f"Could not {verb} controller with name '{name}' because no "
                                          "controller with this name exists")
                            return False
                        _logger.debug(f"Could not {verb} controller with name '{name}' because no "
                                      "controller with this name exists")
                    else:
                        target.append(loaded)
            active = []
            for loaded in self.controllers:
                in_stop, in_start = loaded in stop_list, loaded in start_list
                running = loaded.state == "running"
                if not running and in_stop:
                    if strict:
                        _logger.error(f"Could not stop controller '{loaded.name}' since it is not running")
                        return False
                    in_stop = False
                    stop_list.remove(loaded)
                if running and not in_stop and in_start:
                    if strict:
                        _logger.error(f"Controller '{loaded.name}' is already running")
                        return False
                    in_start = False
                    start_list.remove(loaded)
                if in_stop and in_start:
                    _logger.error(f"Could no start or stop controller '{loaded.name}' because of "
                                  "conflicting switching command")
                    return False
                if in_start or (running and not in_stop):
                    active.append(loaded)
            if self._conflict(active):
                _logger.error("Could not switch controllers, due to resource conflict")
                return False
            done = threading.Event()
            self._switch_request = (stop_list, start_list, done)
        if wait is None:
            done.wait()
            return not self.closed
        if wait(done, timeout):
            return not self.closed
        self._switch_request = None
        return False

    @staticmethod
    def _conflict(active: Sequence[LoadedController]) -> bool:
        claims: Dict[str, List[str]] = {}
        for loaded in active:
            for _, resources in loaded.claimed:
                for resource in resources:
                    claims.setdefault(resource, []).append(loaded.name)
        conflict = False
        for resource, names in sorted(claims.items()):
            if len(names) > 1:
                listed = "".join(name + ", " for name in names)
                _logger.warning(f"Resource conflict on [{resource}].  Controllers = [{listed}]")
                conflict = True
        return conflict

    def list(self) -> List[LoadedController]:
        with self._lock:
            return list(self.controllers)

    def unload_all(self):
        """Stop and unload everything (the model is deleted or the simulator stops)."""
        with self._lock:
            for loaded in self.controllers:
                loaded.controller.close()
            self.controllers = []
            self._updates = []
            self.closed = True
            if self._switch_request is not None:
                # Its caller waits for the loop, which will not run this manager again: answered, not carried out.
                _logger.error("Controller Manager: the model was deleted before the pending controller switch ran; "
                              "nothing was switched")
                self._switch_request[2].set()
                self._switch_request = None

    # -- loop side ---------------------------------------------------------------------------------------
    def update(self, now: float, period: float, reset_controllers: bool = False):
        """Every running controller's update, then a pending switch, as ControllerManager::update."""
        if reset_controllers:
            self.restart_running(now)
        for update in self._updates:
            update(now, period)
        request = self._switch_request
        if request is not None:
            stop_list, start_list, done = request
            for loaded in stop_list:
                if loaded.state == "running":
                    loaded.controller.stop_request(now)
            for loaded in start_list:
                loaded.controller.start_request(now)
            self._updates = [loaded.controller.update for loaded in self.controllers
                             if loaded.state == "running" and type(loaded.controller).update is not Controller.update]
            self._switch_request = None
            done.set()

    def restart_running(self, now: float):
        """Every running controller stopped and started again: it holds (or starts from) where the joints are."""
        for loaded in self.controllers:
            if loaded.state == "running":
                loaded.controller.stop_request(now)
                loaded.controller.start_request(now)


def _join(namespace: str, name: str) -> str:
    return namespace.rstrip("/") + "/" + name
