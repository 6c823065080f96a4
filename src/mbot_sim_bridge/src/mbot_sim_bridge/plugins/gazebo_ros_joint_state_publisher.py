"""``libgazebo_ros_joint_state_publisher.so``: sensor_msgs/JointState of the named joints."""
from sensor_msgs.msg import JointState

from ..core.joints.joint_states import JointStatePublisher
from . import RosPlugin, resolve_in_namespace, ros_time


class GazeboRosJointStatePublisher(RosPlugin, JointStatePublisher):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        self.publisher = self.topics.publisher(resolve_in_namespace(self.namespace, "joint_states"), JointState)
        self.message = JointState(name=self.joint_names)  # refilled at each update

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        message = self.message
        message.header.stamp = ros_time(now)
        states = self.states()
        message.position = [state[0] for state in states]
        message.velocity = [state[1] for state in states]
        message.effort = [state[2] for state in states]
        self.publisher.publish(message)
