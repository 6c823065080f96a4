"""hardware_interface: the joint command interfaces by name, and the error a missing resource raises."""

EFFORT, POSITION, VELOCITY = "EffortJointInterface", "PositionJointInterface", "VelocityJointInterface"
JOINT_STATE = "JointStateInterface"
# Demangled C++ names, as controllers report their interface in list_controllers and in errors.
INTERFACE_TYPES = {name: "hardware_interface::" + name for name in (EFFORT, POSITION, VELOCITY, JOINT_STATE)}
# Gazebo gives a joint without an effort limit an unbounded motor (numeric_limits<double>::max()); Bullet needs
# a number, and this one is far beyond any wheel or arm joint's need while keeping the solver well scaled.
UNBOUNDED_EFFORT = 1.0e5


class HardwareInterfaceError(Exception):
    """hardware_interface::HardwareInterfaceException: a controller asked for a resource that is not there."""
