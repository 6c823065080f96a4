"""``twist_marker``: upstream's arrow (visualization_msgs/Marker on ``marker``, latched, frame base_footprint,
2 m up) pointing along the Twist on ``twist``: x from linear.x, y from linear.y or angular.z, the larger."""
import rospy
from geometry_msgs.msg import Point, Twist
from visualization_msgs.msg import Marker


class TwistMarker:
    def __init__(self, scale: float = 1.0, z: float = 2.0, frame_id: str = "base_footprint"):
        self.marker = Marker(id=0, type=Marker.ARROW, points=[Point(), Point()])
        self.marker.header.frame_id = frame_id
        self.marker.pose.position.z = z
        self.marker.pose.orientation.w = 1.0
        self.marker.scale.x = 0.05 * scale
        self.marker.scale.y = 2 * self.marker.scale.x
        self.marker.color.a, self.marker.color.g = 1.0, 1.0
        self.publisher = rospy.Publisher("marker", Marker, queue_size=1, latch=True)
        rospy.Subscriber("twist", Twist, self._update, queue_size=1)

    def _update(self, twist: Twist):
        tip = self.marker.points[1]
        tip.x = twist.linear.x
        tip.y = twist.linear.y if abs(twist.linear.y) > abs(twist.angular.z) else twist.angular.z
        self.publisher.publish(self.marker)


def main():
    rospy.init_node("twist_marker")
    TwistMarker()
    rospy.spin()
