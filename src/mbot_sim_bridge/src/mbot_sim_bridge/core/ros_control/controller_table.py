"""Controller type string -> core class: every controller the controller manager can load.

Its own module, not the package's ``__init__``: a robot without ros_control (whose mimic joints still use
``control_toolbox``) then does not import every controller at start-up.
"""
from typing import Dict

from .diff_drive_controller import DiffDriveController
from .gripper_action_controller import GripperActionController
from .forward_command_controller import ForwardCommandController, ForwardJointGroupCommandController, forward_type
from .hardware_interface import EFFORT, POSITION, VELOCITY
from .joint_state_controller import JointStateController
from .joint_trajectory_controller import JointTrajectoryController
from .pid_controllers import EffortGroupPositionController, EffortVelocityController, PidPositionController

# The ROS layer has the same keys with its subclasses.
CORE_CONTROLLERS: Dict[str, type] = {
    "joint_state_controller/JointStateController": JointStateController,
    "diff_drive_controller/DiffDriveController": DiffDriveController,
    "position_controllers/JointPositionController":
        forward_type(ForwardCommandController, POSITION, True, "PositionJointPositionController"),
    "position_controllers/JointGroupPositionController":
        forward_type(ForwardJointGroupCommandController, POSITION, True, "PositionJointGroupPositionController"),
    "velocity_controllers/JointVelocityController":
        forward_type(ForwardCommandController, VELOCITY, False, "VelocityJointVelocityController"),
    "velocity_controllers/JointGroupVelocityController":
        forward_type(ForwardJointGroupCommandController, VELOCITY, False, "VelocityJointGroupVelocityController"),
    "velocity_controllers/JointPositionController":
        type("VelocityJointPositionController", (PidPositionController,), {"INTERFACE": VELOCITY}),
    "effort_controllers/JointEffortController":
        forward_type(ForwardCommandController, EFFORT, False, "EffortJointEffortController"),
    "effort_controllers/JointGroupEffortController":
        forward_type(ForwardJointGroupCommandController, EFFORT, False, "EffortJointGroupEffortController"),
    "effort_controllers/JointPositionController":
        type("EffortJointPositionController", (PidPositionController,), {"INTERFACE": EFFORT}),
    "effort_controllers/JointVelocityController": EffortVelocityController,
    "effort_controllers/JointGroupPositionController": EffortGroupPositionController,
    **{f"{kind}_controllers/JointTrajectoryController":
       type(f"{kind.capitalize()}JointTrajectoryController", (JointTrajectoryController,), {"INTERFACE": interface})
       for kind, interface in (("position", POSITION), ("velocity", VELOCITY), ("effort", EFFORT))},
    **{f"{kind}_controllers/GripperActionController":
       type(f"{kind.capitalize()}GripperActionController", (GripperActionController,), {"INTERFACE": interface})
       for kind, interface in (("position", POSITION), ("effort", EFFORT))},
}
