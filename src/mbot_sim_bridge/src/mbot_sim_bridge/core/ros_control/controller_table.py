"""Controller type string -> core class: every controller the controller manager can load.

Its own module, not the package's ``__init__``: a robot without ros_control (whose mimic joints still use
``control_toolbox``) then does not import every controller at start-up.
"""
from typing import Dict

from .ackermann_steering_controller import AckermannSteeringController
from .diff_drive_controller import DiffDriveController
from .gripper_action_controller import GripperActionController
from .four_wheel_steering_controller import FourWheelSteeringController
from .forward_command_controller import ForwardCommandController, ForwardJointGroupCommandController, forward_type
from .hardware_interface import EFFORT, POSITION, VELOCITY
from .joint_state_controller import JointStateController
from .joint_trajectory_controller import JointTrajectoryController
from .pid_controllers import EffortGroupPositionController, EffortVelocityController, PidPositionController

# The ROS layer has the same keys with its subclasses.
CORE_CONTROLLERS: Dict[str, type] = {
    "joint_state_controller/JointStateController": JointStateController,
    "diff_drive_controller/DiffDriveController": DiffDriveController,
    "ackermann_steering_controller/AckermannSteeringController": AckermannSteeringController,
    "four_wheel_steering_controller/FourWheelSteeringController": FourWheelSteeringController,
    "velocity_controllers/JointPositionController":
        type("VelocityJointPositionController", (PidPositionController,), {"INTERFACE": VELOCITY}),
    "effort_controllers/JointPositionController":
        type("EffortJointPositionController", (PidPositionController,), {"INTERFACE": EFFORT}),
    "effort_controllers/JointVelocityController": EffortVelocityController,
    "effort_controllers/JointGroupPositionController": EffortGroupPositionController,
    # position_/velocity_/effort_controllers' forward ones, single joint and group; position starts where it is.
    **{f"{kind}_controllers/Joint{group}{kind.capitalize()}Controller":
       forward_type(base, interface, interface == POSITION,
                    f"{kind.capitalize()}Joint{group}{kind.capitalize()}Controller")
       for kind, interface in (("position", POSITION), ("velocity", VELOCITY), ("effort", EFFORT))
       for group, base in (("", ForwardCommandController), ("Group", ForwardJointGroupCommandController))},
    **{f"{kind}_controllers/JointTrajectoryController":
       type(f"{kind.capitalize()}JointTrajectoryController", (JointTrajectoryController,), {"INTERFACE": interface})
       for kind, interface in (("position", POSITION), ("velocity", VELOCITY), ("effort", EFFORT))},
    **{f"{kind}_controllers/GripperActionController":
       type(f"{kind.capitalize()}GripperActionController", (GripperActionController,), {"INTERFACE": interface})
       for kind, interface in (("position", POSITION), ("effort", EFFORT))},
}
