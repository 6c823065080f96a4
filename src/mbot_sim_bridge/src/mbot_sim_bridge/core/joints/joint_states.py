"""``libgazebo_ros_joint_state_publisher.so`` without ROS: the named joints' states at ``updateRate``.

The bridge also adds one to every robot for the movable joints no other plugin publishes: Gazebo leaves
them to joint_state_publisher, which can only publish zeros (the course's caster, and the wheels fighting
the diff drive), so robot_state_publisher would not see the simulated joints.
"""
from .. import names
from ..clock import UpdateTimer
from ..errors import ConfigError
from ..params import Param, rate
from ..plugin import Plugin

JOINT_STATE_PARAMS = (
    Param("jointName", str, "", "joints to publish, separated by commas"),
    rate("updateRate", 100.0, "Hz of sim time; ≤ 0 = every physics step", signed=True),
    Param("robotNamespace", str, "", "namespace of joint_states; spawn_model sets it", warn_if_missing=False),
)


class JointStatePublisher(Plugin):
    NAMESPACE_RULE = names.MODEL
    GAZEBO_CLASS = "GazeboRosJointStatePublisher"
    PARAMS = JOINT_STATE_PARAMS

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        params = self.read_params()
        self.namespace = self.robot_namespace()
        self.joint_names = [name.strip() for name in params["jointName"].split(",") if name.strip()]
        unknown = [name for name in self.joint_names if name not in context.robot.joint_index]
        if unknown:
            movable = ", ".join(context.robot.movable_joints) or "none"
            raise ConfigError(f"{context.where(element)}: {self.label}: <jointName> names {', '.join(unknown)}, which "
                              f"the robot does not have; movable joints: {movable}")
        self.joint_states_published = tuple(self.joint_names)
        # Strict like the diff drive's timer (one step after each period), so both publish in the same pass.
        self.timer = UpdateTimer(params["updateRate"], strict=True, start=context.simulation.sim_time)

    def states(self):
        """(position, velocity, effort) of each joint, in ``joint_names`` order."""
        return self.context.robot.joint_state(self.joint_names)
