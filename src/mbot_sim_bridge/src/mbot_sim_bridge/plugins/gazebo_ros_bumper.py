"""``libgazebo_ros_bumper.so``: a contact sensor's contacts as gazebo_msgs/ContactsState."""
import rospy
from gazebo_msgs.msg import ContactsState, ContactState
from geometry_msgs.msg import Vector3, Wrench

from ..core.sensors.bumper import Bumper
from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import set_xyz


def _vector(values) -> Vector3:
    vector = Vector3()
    set_xyz(vector, values)
    return vector


def _wrench(force, torque) -> Wrench:
    wrench = Wrench()
    set_xyz(wrench.force, force)
    set_xyz(wrench.torque, torque)
    return wrench


class GazeboRosBumper(RosPlugin, Bumper):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        namespace = self.robot_namespace()
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["bumperTopicName"]),
                                               ContactsState)
        self.frame_id = resolve_frame(self.params["frameName"], tf_prefix(context.simulation.parameters, namespace))
        rospy.loginfo(f"{self.label}: contacts of '{self.collision_name}' -> {self.publisher.resolved_name}")

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        message = ContactsState()
        message.header.stamp = ros_time(now)
        message.header.frame_id = self.frame_id
        for contact in self.latest:
            state = ContactState(collision1_name=contact.collision1, collision2_name=contact.collision2)
            state.info = f"contacts of {contact.collision1} with {contact.collision2} at {now:.3f} s"
            state.wrenches = [_wrench(point.force, point.torque) for point in contact.points]
            state.total_wrench = _wrench([sum(point.force[i] for point in contact.points) for i in range(3)],
                                         [sum(point.torque[i] for point in contact.points) for i in range(3)])
            state.contact_positions = [_vector(point.position) for point in contact.points]
            state.contact_normals = [_vector(point.normal) for point in contact.points]
            state.depths = [point.depth for point in contact.points]
            message.states.append(state)
        self.publisher.publish(message)
