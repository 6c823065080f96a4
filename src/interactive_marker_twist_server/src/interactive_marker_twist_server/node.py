"""The ``marker_server`` node: an interactive marker named ``<robot_name>_twist_marker`` in ``link_name``
(a move_x arrow, move_y/move_z for the axes configured, a rotate_z ring), served under the node's
namespace as ``twist_marker_server``. Each feedback becomes a Twist on ``~cmd_vel`` and the marker snaps
back to the robot, as upstream's C++ node."""
import math

import rospy
from geometry_msgs.msg import Pose, Quaternion, Twist
from interactive_markers.interactive_marker_server import InteractiveMarkerServer
from visualization_msgs.msg import InteractiveMarker, InteractiveMarkerControl

from .twist_from_pose import AXES, Scales, huge_offset, pose_problem, twist_values

# Each control's orientation (w, x, y, z): the axis a MOVE_AXIS or ROTATE_AXIS control works along.
_CONTROLS = (("move_x", InteractiveMarkerControl.MOVE_AXIS, (1, 1, 0, 0), "x"),
             ("move_y", InteractiveMarkerControl.MOVE_AXIS, (1, 0, 0, 1), "y"),
             ("move_z", InteractiveMarkerControl.MOVE_AXIS, (1, 0, 1, 0), "z"),
             ("rotate_z", InteractiveMarkerControl.ROTATE_AXIS, (1, 0, 1, 0), None))


def _number(name: str, default: float) -> float:
    value = rospy.get_param(name, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        rospy.logerr(f"parameter {rospy.resolve_name(name)}: expected a number, got {value!r}; using {default}")
        return default
    return float(value)


def _axis_map(name: str, default: float) -> dict:
    value = rospy.get_param(name, {})
    if not isinstance(value, dict):
        rospy.logerr(f"parameter {rospy.resolve_name(name)}: expected a map of x, y, z to numbers (as "
                     f"linear_scale), got {value!r}; using {default} for every axis")
        value = {}
    values = {}
    for axis, number in value.items():
        if axis not in AXES or isinstance(number, bool) or not isinstance(number, (int, float)) or math.isnan(number):
            rospy.logerr(f"parameter {rospy.resolve_name(name)}/{axis}: expected x, y or z with a number, got "
                         f"{number!r}; left out")
        else:
            values[axis] = float(number)
    return values


def read_scales() -> Scales:
    """Upstream's parameters: a map ``linear_scale`` (and the two limit maps) drives the axes it names; a number
    drives x only."""
    scales = Scales(angular=_number("~angular_scale", 2.2), max_angular=_number("~max_angular_velocity", 2.2))
    if isinstance(rospy.get_param("~linear_scale", None), dict):
        scales.linear = _axis_map("~linear_scale", 1.0)
        positive = _axis_map("~max_positive_linear_velocity", 1.0)
        negative = _axis_map("~max_negative_linear_velocity", -1.0)
        for axis in scales.linear:
            for limits, name in ((positive, "max_positive_linear_velocity"),
                                 (negative, "max_negative_linear_velocity")):
                if axis not in limits:
                    rospy.logwarn(f"parameter {rospy.resolve_name('~' + name)} has no {axis}: 0 is used, as "
                                  "upstream does, so that direction is stopped")
        scales.max_positive_linear = {axis: positive.get(axis, 0.0) for axis in scales.linear}
        scales.max_negative_linear = {axis: negative.get(axis, 0.0) for axis in scales.linear}
    else:
        scales.linear = {"x": _number("~linear_scale", 1.0)}
        scales.max_positive_linear = {"x": _number("~max_positive_linear_velocity", 1.0)}
        scales.max_negative_linear = {"x": _number("~max_negative_linear_velocity", -1.0)}
    return scales


class MarkerServer:
    def __init__(self):
        self.link_name = rospy.get_param("~link_name", "base_link")
        self.robot_name = rospy.get_param("~robot_name", "robot")
        self.scales = read_scales()
        self.marker_size_scale = _number("~marker_size_scale", 1.0)
        self.publisher = rospy.Publisher("~cmd_vel", Twist, queue_size=1)
        self.marker_name = f"{self.robot_name}_twist_marker"
        self._warned = set()
        self.server = InteractiveMarkerServer("twist_marker_server")
        self.server.insert(self._marker(), self._on_feedback)
        self.server.applyChanges()
        rospy.loginfo("[twist_marker_server] Initialized.")

    def _marker(self) -> InteractiveMarker:
        marker = InteractiveMarker(name=self.marker_name, description=f"twist controller for {self.robot_name}",
                                   scale=self.marker_size_scale)
        marker.header.frame_id = self.link_name
        for name, mode, (w, x, y, z), axis in _CONTROLS:
            if axis is None or axis in self.scales.linear:
                control = InteractiveMarkerControl(name=name, interaction_mode=mode,
                                                   orientation_mode=InteractiveMarkerControl.FIXED)
                control.orientation.w, control.orientation.x = w, x
                control.orientation.y, control.orientation.z = y, z
                marker.controls.append(control)
        return marker

    def _on_feedback(self, feedback):
        position = (feedback.pose.position.x, feedback.pose.position.y, feedback.pose.position.z)
        orientation = (feedback.pose.orientation.x, feedback.pose.orientation.y, feedback.pose.orientation.z,
                       feedback.pose.orientation.w)
        problem = pose_problem(position, orientation)
        if problem is None:
            linear, angular = twist_values(self.scales, position, orientation)
            twist = Twist()
            for axis, value in linear.items():
                setattr(twist.linear, axis, value)
            twist.angular.z = angular
            self.publisher.publish(twist)
            huge = huge_offset(position)
            if huge is not None and "huge" not in self._warned:
                self._warned.add("huge")
                rospy.logwarn(f"marker_server: feedback from {feedback.client_id or 'a client'}: {huge}; the Twist "
                              "is clamped to the limits (said once)")
        elif problem not in self._warned:
            self._warned.add(problem)
            rospy.logwarn(f"marker_server: feedback from {feedback.client_id or 'a client'} on "
                          f"{rospy.resolve_name('twist_marker_server/feedback')}: {problem}; no Twist sent for it "
                          "(said once)")
        # The marker snaps back to the robot (upstream sets a default Pose, whose quaternion is all zeros; rviz
        # takes the identity better).
        self.server.setPose(self.marker_name, Pose(orientation=Quaternion(w=1.0)))
        self.server.applyChanges()


def main():
    rospy.init_node("marker_server")
    MarkerServer()
    rospy.spin()
