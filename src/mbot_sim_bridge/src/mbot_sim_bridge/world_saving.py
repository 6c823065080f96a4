"""/gazebo/save_world (mbot_sim_msgs/SaveWorld): the bridge's own service for Gazebo's "File > Save world as".

Gazebo saves from its GUI menu and gazebo_ros has no service for it; this one is the bridge's. The loop
thread takes a snapshot (every world model's description and pose now, the URDF robots' link poses); the
SDF is written in the service's thread by ``core.description.world_writer``, to a temp file renamed over the target.
"""
import os
from typing import Callable

import rospy
from mbot_sim_msgs.srv import SaveWorldResponse

from .core.errors import BridgeError, WorldError
from .core.description.world_description import WorldDescription
from .core.description.world_writer import WorldSnapshot, take_snapshot, world_sdf, write_world_file

PLUGINS_AS_TAGS = ("robots are written as inline SDF models; their plugins are kept as <plugin> tags, which "
                   "Gazebo loads but the bridge does not run for SDF models")


class SaveWorldHandler:
    """The ``~save_world`` handler: ``rospy.Service("~save_world", SaveWorld, SaveWorldHandler(world, sim,
    node.call_in_loop))``. ``world`` is the description the simulation was loaded from (its name, scene and
    other elements are written back; lights and physics as they are now); ``simulation`` a core Simulation, read
    only through ``call_in_loop``."""

    def __init__(self, world: WorldDescription, simulation, call_in_loop: Callable):
        self.world = world
        self.simulation = simulation
        self.call_in_loop = call_in_loop

    def __call__(self, request) -> SaveWorldResponse:
        try:
            message = self.save(request.path, request.with_robots)
        except BridgeError as error:
            rospy.logerr(f"save_world: {error}")
            return SaveWorldResponse(success=False, status_message=str(error))
        rospy.loginfo(f"save_world: {message}")
        return SaveWorldResponse(success=True, status_message=message)

    def save(self, path: str, with_robots: bool) -> str:
        if not os.path.isabs(path):
            raise WorldError(f"path '{path}' is not absolute (the simulator's working directory is not the caller's)")
        snapshot: WorldSnapshot = self.call_in_loop(lambda: take_snapshot(self.simulation, with_robots))
        write_world_file(path, world_sdf(self.world, snapshot.models, snapshot.poses, snapshot.robots,
                                         snapshot.link_states, snapshot.physics, snapshot.lights))
        left_out = [] if with_robots else snapshot.robot_names
        message = f"wrote {path}: {len(snapshot.models) + len(snapshot.robots)} models"
        if left_out:
            message += f"; robots left out (with_robots adds them): {', '.join(left_out)}"
        if snapshot.robots:
            rospy.logwarn(f"save_world: {PLUGINS_AS_TAGS}")
            message += "; warning: " + PLUGINS_AS_TAGS
        return message
