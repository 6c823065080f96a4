"""``libhector_gazebo_ros_sonar.so``: a ray sensor's nearest reading as sensor_msgs/Range, in its frameId."""
from ..core.sensors.range_sensor import HectorSonar
from .gazebo_ros_range import RangePublisher


class HectorGazeboRosSonar(RangePublisher, HectorSonar):
    def __init__(self, context, element, sensor):
        super().__init__(context, element, sensor)
        self.advertise(self.params["topicName"], self.params["frameId"])
