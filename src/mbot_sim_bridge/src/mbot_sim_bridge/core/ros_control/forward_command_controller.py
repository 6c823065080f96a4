"""forward_command_controller: the position/velocity/effort ``Joint*Controller`` and ``JointGroup*Controller``
that pass their command straight to the joint."""
from typing import List, Optional, Sequence

from .controller_manager import ControllerInitError
from .controller_interface import Controller


def joint_name_param(params: dict, namespace: str) -> str:
    joint = params.get("joint")
    if not isinstance(joint, str):
        raise ControllerInitError(f"No joint given (namespace: {namespace})")
    return joint


def joint_names_param(params: dict, namespace: str) -> List[str]:
    joints = params.get("joints")
    if not isinstance(joints, list) or not all(isinstance(joint, str) for joint in joints):
        raise ControllerInitError(f"Failed to getParam 'joints' (namespace: {namespace}).")
    if not joints:
        raise ControllerInitError("List of joint names is empty.")
    return list(joints)


class ForwardCommandController(Controller):
    """forward_command_controller: ``command`` (std_msgs/Float64) goes to the joint as it is."""

    START_AT_POSITION = False  # position controllers start by holding where the joint is; the others at 0

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self.namespace = context.namespace
        self.joint = self.handle(joint_name_param(params, self.namespace))
        self.command = 0.0

    def set_command(self, value: float):
        if self.finite_command([self.joint.name], [value]):
            self.command = value

    def starting(self, now):
        self.command = self.joint.position if self.START_AT_POSITION else 0.0

    def update(self, now, period):
        self.joint.command = self.command


class ForwardJointGroupCommandController(Controller):
    """forward_joint_group_command_controller: ``command`` (std_msgs/Float64MultiArray), one value per joint."""

    START_AT_POSITION = False

    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context)
        self.namespace = context.namespace
        self.joint_names = joint_names_param(params, self.namespace)
        self.joints = [self._group_handle(joint) for joint in self.joint_names]
        self.commands = [0.0] * len(self.joints)

    def _group_handle(self, joint):
        try:
            return self.handle(joint)
        except Exception as error:  # upstream catches HardwareInterfaceException here and fails init
            raise ControllerInitError(f"Exception thrown: {error}") from None

    def set_commands(self, values: Sequence[float]) -> Optional[str]:
        """None when taken or refused for a value that is not finite (said once); else upstream's complaint."""
        if len(values) != len(self.joints):
            return (f"Dimension of command ({len(values)}) does not match number of joints "
                    f"({len(self.joints)})! Not executing!")
        if self.finite_command(self.joint_names, values):
            self.commands = list(values)
        return None

    def starting(self, now):
        self.commands = [joint.position if self.START_AT_POSITION else 0.0 for joint in self.joints]

    def update(self, now, period):
        for joint, command in zip(self.joints, self.commands):
            joint.command = command


def forward_type(base: type, interface: str, start_at_position: bool, name: str) -> type:
    return type(name, (base,), {"INTERFACE": interface, "START_AT_POSITION": start_at_position})
