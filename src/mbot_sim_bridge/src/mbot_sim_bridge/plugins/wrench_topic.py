"""The ROS side the wrench plugins share (f3d, ft sensor): their core leaves ``latest`` (force, torque), published
as geometry_msgs/WrenchStamped at each update while someone subscribes; without subscribers the core idles."""
from geometry_msgs.msg import WrenchStamped

from ..core.names import resolve_frame, tf_prefix
from . import RosPlugin, resolve_in_namespace, ros_time
from .messages import set_xyz


class WrenchTopic(RosPlugin):
    def advertise_wrench(self, context, frame: str):
        """The topic (``topicName`` in the robot's namespace) and the header frame (with the tf prefix)."""
        namespace = self.robot_namespace()
        self.message = WrenchStamped()
        self.message.header.frame_id = resolve_frame(frame, tf_prefix(context.simulation.parameters, namespace))
        self.publisher = self.topics.publisher(resolve_in_namespace(namespace, self.params["topicName"]),
                                               WrenchStamped)

    def update(self, now: float):
        if self.nobody_listens(now, self.publisher):
            return
        super().update(now)
        self.message.header.stamp = ros_time(now)
        set_xyz(self.message.wrench.force, self.latest.force)
        set_xyz(self.message.wrench.torque, self.latest.torque)
        self.publisher.publish(self.message)
