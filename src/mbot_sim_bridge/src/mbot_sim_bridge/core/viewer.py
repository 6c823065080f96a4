"""The simulator window (PyBullet's GUI) as Gazebo's client shows it: Gazebo colours, camera on the robot."""
import math
import time

import pybullet

from .engine import Engine, SpawnedRobot
from .geometry import yaw
from .description.materials import colour_robot

# Close enough to see the 0.32 m mbot and what is around it, from behind and above.
_CAMERA_DISTANCE, _CAMERA_PITCH_DEGREES = 1.2, -30.0
_FOLLOW_PERIOD_SECONDS = 1.0 / 30.0
# The window applies a camera change asynchronously; until then it still reports the old camera.
_CAMERA_SETTLE_SECONDS = 1.0


class Viewer:
    def __init__(self, engine: Engine):
        self.engine = engine
        client = engine.client
        # A clean view: no side panels and preview windows, as gzclient shows only the scene.
        client.configureDebugVisualizer(pybullet.COV_ENABLE_GUI, 0)
        self.followed = None
        self._last_follow = 0.0
        self._camera = (_CAMERA_DISTANCE, 0.0, _CAMERA_PITCH_DEGREES)  # distance, yaw, pitch (degrees)
        self._camera_settled_at = 0.0

    def show_robot(self, robot: SpawnedRobot):
        """Gazebo materials (``<gazebo reference><material>Gazebo/X``) on the links that set one; the first
        robot shown is the one the camera follows.

        PyBullet colours a link's visuals as a whole, so links lumped together (the course's base_link and
        laser_link into base_footprint) take the material of the heaviest of them.
        """
        colour_robot(robot)
        if self.followed is None:
            self.followed = robot
            # Behind the robot, looking along its heading.
            self._camera = (_CAMERA_DISTANCE, math.degrees(yaw(robot.root_pose().orientation)) - 90.0,
                            _CAMERA_PITCH_DEGREES)
            self._camera_settled_at = time.monotonic() + _CAMERA_SETTLE_SECONDS
            self._aim(robot)

    def forget_robot(self, robot: SpawnedRobot):
        if self.followed is robot:
            self.followed = None

    def follow(self):
        """Keep the camera on the followed robot, at most 30 times a wall second.

        Only the target moves: distance and angles stay as the user leaves them with the mouse.
        """
        now = time.monotonic()
        if self.followed is None or now - self._last_follow < _FOLLOW_PERIOD_SECONDS:
            return
        self._last_follow = now
        if now > self._camera_settled_at:
            camera = self.engine.client.getDebugVisualizerCamera()
            if camera[0] > 0:  # a window that has not reported its camera yet answers zeros (distance 0)
                self._camera = (camera[10], camera[8], camera[9])
        self._aim(self.followed)

    def _aim(self, robot: SpawnedRobot):
        distance, yaw_degrees, pitch_degrees = self._camera
        self.engine.client.resetDebugVisualizerCamera(distance, yaw_degrees, pitch_degrees, robot.root_pose().position)
