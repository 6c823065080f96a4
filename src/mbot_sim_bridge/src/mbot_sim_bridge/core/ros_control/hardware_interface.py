"""hardware_interface: the joint command interfaces by name, and the error a missing resource raises."""

EFFORT, POSITION, VELOCITY = "EffortJointInterface", "PositionJointInterface", "VelocityJointInterface"
JOINT_STATE = "JointStateInterface"
# Demangled C++ names, as controllers report their interface in list_controllers and in errors.
INTERFACE_TYPES = {name: "hardware_interface::" + name for name in (EFFORT, POSITION, VELOCITY, JOINT_STATE)}
# Gazebo gives a joint without an effort limit an unbounded motor (numeric_limits<double>::max()); Bullet needs
# a number, and this one is far beyond any wheel or arm joint's need while keeping the solver well scaled.
UNBOUNDED_EFFORT = 1.0e5
# PyBullet's default maxJointVelocity (rad/s or m/s): the engine clamps joint speeds there, and a velocity motor
# asked for far more (1e308) pushes the solver until the model flies off.
MAX_JOINT_SPEED = 100.0


class HardwareInterfaceError(Exception):
    """hardware_interface::HardwareInterfaceException: a controller asked for a resource that is not there."""
