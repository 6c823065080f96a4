"""The bridge's own joint-state publisher: every movable joint that no plugin already publishes.

Gazebo leaves these joints to joint_state_publisher, which can only publish zeros (the course's caster,
and the wheels fighting the diff drive). The bridge publishes their simulated state instead, so that
robot_state_publisher builds the whole tree from one publisher per joint.
"""
from sensor_msgs.msg import JointState

from ..core.clock import UpdateTimer
from . import BridgePlugin, PluginContext, loop_publisher, resolve_in_namespace


class ModelJointStatePublisher(BridgePlugin):
    def __init__(self, context: PluginContext, joint_names, rate: float):
        self.context = context
        self.joint_names = list(joint_names)
        # Timed like the diff drive (one step after each period), so both publish in the same loop pass.
        self.timer = UpdateTimer(rate, strict=True, start=context.engine.sim_time)
        self.publisher = loop_publisher(resolve_in_namespace(context.robot.namespace, "joint_states"), JointState)

    def update(self, now: float):
        message = JointState()
        message.header.stamp = self.context.stamp()
        message.name = self.joint_names
        states = self.context.robot.joint_state(self.joint_names)
        message.position = [state[0] for state in states]
        message.velocity = [state[1] for state in states]
        message.effort = [state[2] for state in states]
        self.publisher.publish(message)

    def close(self):
        self.publisher.unregister()
