"""ackermann_steering_controller/AckermannSteeringController: one rear wheel joint (velocity) and one front steering
joint (position), a bicycle model. As upstream, cmd_vel's angular.z is the steering angle given to the steering
joint (through the angular limiter), not a yaw rate: the robot then turns at linear·tan(angle)/wheel_separation_h.
The odometry integrates the rear wheel's travel with that yaw rate; the rest (publish rate, open loop, limits,
timeout, frames) is diff_drive_controller's, as upstream copied it."""
import math
from typing import Optional

from ..description.robot_model import RobotModel
from ..log import get_logger
from .controller_interface import param
from .controller_manager import ControllerInitError
from .diff_drive_controller import DiffDriveOdometry, TwistController
from .hardware_interface import POSITION

_logger = get_logger(__name__)


class AckermannOdometry(DiffDriveOdometry):
    """ackermann_steering_controller::Odometry: the rear wheel's travel, turned by the steering angle."""

    def set_wheel_params(self, separation_h: float, radius: float):
        self.wheel_separation, self.left_radius = separation_h, radius

    def update(self, rear_wheel_position: float, steering_position: float, now: float) -> bool:
        travel = rear_wheel_position * self.left_radius
        linear, self.left_old = travel - self.left_old, travel
        return self.integrate_speeds(linear, math.tan(steering_position) * linear / self.wheel_separation, now)


class AckermannSteeringController(TwistController):
    def __init__(self, name, hw, params, context):
        super().__init__(name, hw, params, context, AckermannOdometry())

        def get(key, default, kind=float):
            return param(params, key, default, kind, name)
        rear_wheel = get("rear_wheel", "rear_wheel_joint", str)
        front_steer = get("front_steer", "front_steer_joint", str)
        self.wheel_separation_h_multiplier = get("wheel_separation_h_multiplier", 1.0)
        self.wheel_radius_multiplier = get("wheel_radius_multiplier", 1.0)
        self.steer_pos_multiplier = get("steer_pos_multiplier", 1.0)
        self.wheel_separation_h = get("wheel_separation_h", None)
        self.wheel_radius = get("wheel_radius", None)
        self._geometry_from_urdf(context.urdf, rear_wheel, front_steer)
        separation_h = self.wheel_separation_h_multiplier * self.wheel_separation_h
        radius = self.wheel_radius_multiplier * self.wheel_radius
        self.odometry.set_wheel_params(separation_h, radius)
        _logger.info(f"{name}: Odometry params : wheel separation height {separation_h}, wheel radius {radius}")
        self.rear_wheel = self.handle(rear_wheel)
        self.front_steer = self.handle(front_steer, POSITION)

    def _geometry_from_urdf(self, urdf: Optional[RobotModel], rear_wheel: str, front_steer: str):
        if self.wheel_separation_h is not None and self.wheel_radius is not None:
            return
        if urdf is None:
            raise ControllerInitError("Robot descripion couldn't be retrieved from param server.")
        rear_joint, steer_joint = urdf.joints.get(rear_wheel), urdf.joints.get(front_steer)
        for joint, joint_name in ((rear_joint, rear_wheel), (steer_joint, front_steer)):
            if joint is None:
                raise ControllerInitError(f"{joint_name} couldn't be retrieved from model description")
        if self.wheel_separation_h is None:
            # upstream: the x distance of the two joints' origins in their parents' frames
            self.wheel_separation_h = abs(rear_joint.origin.position[0] - steer_joint.origin.position[0])
        if self.wheel_radius is None:
            wheel = urdf.links[rear_joint.child]
            if not wheel.collision_kinds:
                raise ControllerInitError(f"Link {rear_joint.child} does not have collision description. Add "
                                          f"collision description for link to urdf.\nCouldn't retrieve {rear_wheel} "
                                          "wheel radius")
            if wheel.collision_kinds[0] != "cylinder":
                raise ControllerInitError(f"Wheel link {rear_joint.child} is NOT modeled as a cylinder!\n"
                                          f"Couldn't retrieve {rear_wheel} wheel radius")
            self.wheel_radius = wheel.collision_radii[0]
        if not (self.wheel_separation_h > 0 and self.wheel_radius > 0):
            # upstream would divide by zero in the odometry and the wheel command
            raise ControllerInitError(f"wheel_separation_h {self.wheel_separation_h} and wheel_radius "
                                      f"{self.wheel_radius} must both be positive")

    def brake(self):
        self.rear_wheel.command = 0.0
        self.front_steer.command = 0.0

    def update(self, now, period):
        odometry = self.odometry
        if self.open_loop:
            odometry.update_open_loop(self.last0[0], self.last0[1], now)
        else:
            wheel, steer = self.rear_wheel.position, self.front_steer.position
            if math.isnan(wheel) or math.isnan(steer):
                return
            odometry.update(wheel, steer * self.steer_pos_multiplier, now)
        self.sample_odometry(now)
        linear, angle = self.limited_command(now, period)
        # upstream divides by the radius without its multiplier
        self.rear_wheel.command = linear / self.wheel_radius
        self.front_steer.command = angle
