"""gazebo_ros's ROS API (``libgazebo_ros_api_plugin.so``): the /gazebo/* services and model_states.

Handlers run in rospy's threads; each converts the request into Simulation calls that run in the loop
thread (``node.call_in_loop``) and the result back into a response.
"""
import math
import tempfile
from typing import Optional
from xml.etree import ElementTree

import rospy
from gazebo_msgs.srv import (ApplyBodyWrench, ApplyBodyWrenchResponse, BodyRequest, BodyRequestResponse,
                             DeleteModel, DeleteModelResponse, GetModelState, GetModelStateResponse,
                             GetPhysicsProperties, GetPhysicsPropertiesResponse, GetWorldProperties,
                             GetWorldPropertiesResponse, SetModelState, SetModelStateResponse, SpawnModel,
                             SpawnModelResponse)
from gazebo_msgs.srv import (GetLinkState, GetLinkStateResponse, GetModelProperties, GetModelPropertiesResponse,
                             SetModelConfiguration, SetModelConfigurationResponse)
from geometry_msgs.msg import Pose as PoseMessage
from mbot_sim_msgs.srv import SaveWorld, StepSimulation, StepSimulationResponse
from geometry_msgs.msg import Twist
from std_srvs.srv import Empty, EmptyResponse

from .core.engine import check_model_name, check_state
from .core.errors import BridgeError, ModelError
from .core.geometry import IDENTITY, Pose, compose, inverse, rotate
from .gazebo_paths import model_path
from .core.description.robot_model import parse_robot
from .core.description.sdf_spawn import spawn_world_xml
from .core.description.sdf_world import parse_world
from .model_states import ModelStatesPublisher
from .package_uris import resolve_package_uris
from .plugins import ros_time
from .subscriptions import drain
from .world_saving import SaveWorldHandler

_WORLD_FRAMES = ("", "world", "map", "/map")
# How long a step request waits for the bridge's subscribers to handle what reached them.
LOCKSTEP_DRAIN_SECONDS = 5.0
# One step_simulation call covers at most this much sim time: the largest uint32 count would hold the
# simulator (and every other request) for days.
MAX_STEP_SIM_SECONDS = 3600.0
# Upstream's answer; the joints a request names but the model lacks are added after it.
SET_MODEL_CONFIGURATION_SUCCESS = "SetModelConfiguration: success"


def _pose_from_message(message: PoseMessage) -> Pose:
    """The pose with its quaternion normalised, as gazebo_ros does; a zero quaternion is the identity."""
    q = message.orientation
    # Scaled by the largest component first: four components of 1e308 normalise, and hypot does not overflow.
    largest = max(abs(q.x), abs(q.y), abs(q.z), abs(q.w))
    scaled = (q.x, q.y, q.z, q.w) if largest in (0.0, math.inf) else tuple(v / largest for v in (q.x, q.y, q.z, q.w))
    norm = math.hypot(*scaled)
    # A non-finite component stays non-finite here, and check_state refuses it by name.
    orientation = (0.0, 0.0, 0.0, 1.0) if norm == 0 else tuple(v / norm for v in scaled)
    return Pose((message.position.x, message.position.y, message.position.z), orientation)


def _pose_to_message(pose: Pose) -> PoseMessage:
    message = PoseMessage()
    message.position.x, message.position.y, message.position.z = pose.position
    (message.orientation.x, message.orientation.y, message.orientation.z,
     message.orientation.w) = pose.orientation
    return message


def _twist_message(linear, angular) -> Twist:
    twist = Twist()
    twist.linear.x, twist.linear.y, twist.linear.z = (float(v) for v in linear)
    twist.angular.x, twist.angular.y, twist.angular.z = (float(v) for v in angular)
    return twist


class GazeboRosApi:
    def __init__(self, node):
        self.node = node
        self.sim = node.sim
        self.model_states = ModelStatesPublisher(self.sim)
        self._services = [
            rospy.Service("~spawn_urdf_model", SpawnModel, self._spawn_urdf_model),
            rospy.Service("~spawn_sdf_model", SpawnModel, self._spawn_sdf_model),
            rospy.Service("~delete_model", DeleteModel, self._delete_model),
            rospy.Service("~get_model_state", GetModelState, self._get_model_state),
            rospy.Service("~set_model_state", SetModelState, self._set_model_state),
            rospy.Service("~get_world_properties", GetWorldProperties, self._get_world_properties),
            rospy.Service("~get_physics_properties", GetPhysicsProperties, self._get_physics_properties),
            rospy.Service("~pause_physics", Empty, self._empty(lambda: node.set_paused(True))),
            rospy.Service("~unpause_physics", Empty, self._empty(lambda: node.set_paused(False))),
            rospy.Service("~reset_simulation", Empty, self._empty(lambda: node.reset(simulation=True))),
            rospy.Service("~reset_world", Empty, self._empty(lambda: node.reset(simulation=False))),
            rospy.Service("~apply_body_wrench", ApplyBodyWrench, self._apply_body_wrench),
            rospy.Service("~clear_body_wrenches", BodyRequest, self._clear_body_wrenches),
            rospy.Service("~step_simulation", StepSimulation, self._step_simulation),
            rospy.Service("~set_model_configuration", SetModelConfiguration, self._set_model_configuration),
            rospy.Service("~get_model_properties", GetModelProperties, self._get_model_properties),
            rospy.Service("~get_link_state", GetLinkState, self._get_link_state),
            # The bridge's own; the loaded world's description is read again for its lights, scene and name.
            rospy.Service("~save_world", SaveWorld, SaveWorldHandler(self.sim.world, self.sim, node.call_in_loop)),
        ]

    def _empty(self, action):
        def handle(_request):
            self.node.call_in_loop(action)
            return EmptyResponse()
        return handle

    def _guarded(self, response_type, action, timeout: Optional[float] = 30.0):
        """Run ``action`` in the loop thread; a BridgeError becomes success=false with its message."""
        try:
            return self.node.call_in_loop(action, timeout)
        except BridgeError as error:
            return _refused(response_type, error)

    # -- spawn and delete -------------------------------------------------------------------------------------
    def _new_model_pose(self, request) -> Pose:
        """The world pose a SpawnModel request asks for, once its name is known to be free."""
        if request.model_name in self.sim.model_names():
            raise ModelError(f"SpawnModel: Failure - entity already exists: {request.model_name}")
        check_model_name("SpawnModel", request.model_name)
        requested = _pose_from_message(request.initial_pose)
        # Checked as sent too: composed with the reference frame, 1e300 would turn inf and NaN and be named so.
        check_state(f"SpawnModel: model '{request.model_name}'", requested)
        pose = compose(self._reference_pose(request.reference_frame), requested)
        check_state(f"SpawnModel: model '{request.model_name}'", pose)
        return pose

    def _spawn_urdf_model(self, request):
        name, namespace = request.model_name, request.robot_namespace
        try:
            # Read in this service thread, not the loop's: a description of 50 MB stopped /clock for 25 s.
            model = parse_robot(resolve_package_uris(request.model_xml), f"model '{name}'")
        except BridgeError as error:
            return _refused(SpawnModelResponse, error)
        if namespace:
            _inject_namespace(model, namespace)

        def spawn():
            pose = self._new_model_pose(request)
            self.sim.spawn_robot(model, name, pose, namespace or "/")
            return SpawnModelResponse(success=True, status_message="SpawnModel: Successfully spawned entity")
        return self._guarded(SpawnModelResponse, spawn)

    def _spawn_sdf_model(self, request):
        """A model placed as gazebo_ros places it; one with joints, sensors or plugins is spawned as a robot."""
        def spawn():
            name = request.model_name
            pose = self._new_model_pose(request)
            world_xml = spawn_world_xml(resolve_package_uris(request.model_xml), name, pose, request.robot_namespace)
            # The world loader reads files (relative URIs resolve against them); a private temp file holds it.
            with tempfile.NamedTemporaryFile("w", prefix="mbot_spawn_", suffix=".world") as world_file:
                world_file.write(world_xml)
                world_file.flush()
                description = parse_world(world_file.name, model_path())
            if name not in self.sim.add_world(description, request.robot_namespace or "/"):
                raise ModelError(f"model '{name}' has no collision geometry; nothing to simulate")
            rospy.loginfo(f"spawned SDF model '{name}' at {tuple(round(v, 3) for v in pose.position)}")
            return SpawnModelResponse(success=True, status_message="SpawnModel: Successfully spawned entity")
        return self._guarded(SpawnModelResponse, spawn)

    def _delete_model(self, request):
        def delete():
            self.sim.delete(request.model_name)
            return DeleteModelResponse(success=True, status_message="DeleteModel: successfully deleted model")
        return self._guarded(DeleteModelResponse, delete)

    # -- lockstep --------------------------------------------------------------------------------------------
    def _step_simulation(self, request):
        """The bridge's own: exactly ``steps`` physics steps of the paused simulation, after the messages that
        reached the bridge before the request (see subscriptions.drain)."""
        if not drain(timeout=LOCKSTEP_DRAIN_SECONDS):
            rospy.logwarn("step_simulation: subscribers still busy after "
                          f"{LOCKSTEP_DRAIN_SECONDS:.0f} s; stepping anyway")

        def step():
            if self.node.steps_left:
                raise ModelError(f"StepSimulation: another step_simulation is under way ({self.node.steps_left} steps "
                                 "left); call again once it has answered")
            if not self.sim.paused:
                raise ModelError("StepSimulation: the simulation is running; pause it (or start with "
                                 "lockstep:=true) to step it")
            most = int(MAX_STEP_SIM_SECONDS / self.sim.step_size)
            if request.steps > most:
                raise ModelError(f"StepSimulation: {request.steps} steps is more than one call takes ({most}, "
                                 f"{MAX_STEP_SIM_SECONDS:.0f} s of sim time); step in parts")
            self.node.step(request.steps)
            return StepSimulationResponse(success=True, sim_time=self.sim.sim_time,
                                          status_message=f"StepSimulation: {request.steps} steps done")
        # No time limit: the caller asked for that many steps and waits for them, however long they take.
        return self._guarded(StepSimulationResponse, step, timeout=None)

    # -- state queries ---------------------------------------------------------------------------------------
    def _reference_pose(self, frame: str) -> Pose:
        if frame in _WORLD_FRAMES:
            return IDENTITY
        if frame in self.sim.model_names():
            return self.sim.engine.model_pose(frame)
        raise ModelError(f"reference frame '{frame}' is neither the world nor a model")

    def _get_model_state(self, request):
        def get():
            engine = self.sim.engine
            reference = inverse(self._reference_pose(request.relative_entity_name))
            pose = compose(reference, engine.model_pose(request.model_name))
            linear, angular = engine.model_velocity(request.model_name)
            linear, angular = rotate(reference.orientation, linear), rotate(reference.orientation, angular)
            response = GetModelStateResponse(pose=_pose_to_message(pose), twist=_twist_message(linear, angular),
                                             success=True, status_message="GetModelState: got properties")
            response.header.stamp = ros_time(self.sim.sim_time)
            response.header.frame_id = request.relative_entity_name
            return response
        return self._guarded(GetModelStateResponse, get)

    def _set_model_state(self, request):
        state = request.model_state

        def set_state():
            reference = self._reference_pose(state.reference_frame)
            requested, twist = _pose_from_message(state.pose), state.twist
            linear, angular = ((twist.linear.x, twist.linear.y, twist.linear.z),
                               (twist.angular.x, twist.angular.y, twist.angular.z))
            # Checked as sent too: transformed, 1e300 would turn inf and NaN, and on other axes.
            check_state(f"SetModelState: model '{state.model_name}'", requested, linear, angular)
            pose = compose(reference, requested)
            linear, angular = rotate(reference.orientation, linear), rotate(reference.orientation, angular)
            self.sim.set_model_state(state.model_name, pose, linear, angular)
            return SetModelStateResponse(success=True, status_message="SetModelState: set model state done")
        return self._guarded(SetModelStateResponse, set_state)

    # -- wrenches ----------------------------------------------------------------------------------------------
    def _apply_body_wrench(self, request):
        def apply():
            values = [request.reference_point.x, request.reference_point.y, request.reference_point.z]
            force, torque = request.wrench.force, request.wrench.torque
            values += [force.x, force.y, force.z, torque.x, torque.y, torque.z]
            start, duration = request.start_time.to_sec(), request.duration.to_sec()
            self.sim.apply_body_wrench(request.body_name, request.reference_frame, values[:3], values[3:6],
                                       values[6:], start, duration)
            return ApplyBodyWrenchResponse(success=True, status_message="")
        return self._guarded(ApplyBodyWrenchResponse, apply)

    def _clear_body_wrenches(self, request):
        self.node.call_in_loop(lambda: self.sim.clear_body_wrenches(request.body_name))
        return BodyRequestResponse()

    def _get_world_properties(self, _request):
        def get():
            return GetWorldPropertiesResponse(sim_time=self.sim.sim_time, model_names=self.sim.model_names(),
                                              rendering_enabled=True, success=True, status_message="")
        return self._guarded(GetWorldPropertiesResponse, get)

    def _get_physics_properties(self, _request):
        def get():
            physics = self.sim.engine.physics
            response = GetPhysicsPropertiesResponse(time_step=physics.max_step_size, pause=self.sim.paused,
                                                    max_update_rate=physics.real_time_update_rate,
                                                    success=True, status_message="")
            response.gravity.x, response.gravity.y, response.gravity.z = physics.gravity
            ode = response.ode_config
            ode.erp, ode.contact_max_correcting_vel = physics.erp, physics.contact_max_correcting_vel
            ode.contact_surface_layer = physics.contact_surface_layer
            return response
        return self._guarded(GetPhysicsPropertiesResponse, get)

    # -- joints --------------------------------------------------------------------------------------------------
    def _set_model_configuration(self, request):
        def set_configuration():
            missing = self.sim.set_model_configuration(request.model_name, request.joint_names,
                                                       request.joint_positions)
            message = SET_MODEL_CONFIGURATION_SUCCESS
            if missing:
                message += (f"; model '{request.model_name}' has no movable joint "
                            f"{', '.join(repr(name) for name in missing)} (ignored)")
                rospy.logwarn(message)
            return SetModelConfigurationResponse(success=True, status_message=message)
        return self._guarded(SetModelConfigurationResponse, set_configuration)

    # -- model and link queries ------------------------------------------------------------------------------------
    def _get_model_properties(self, request):
        def get():
            properties = self.sim.model_properties(request.model_name)
            return GetModelPropertiesResponse(body_names=properties.body_names, geom_names=properties.geom_names,
                                              joint_names=properties.joint_names, is_static=properties.is_static,
                                              success=True, status_message="GetModelProperties: got properties")
        return self._guarded(GetModelPropertiesResponse, get)

    def _get_link_state(self, request):
        def get():
            pose, linear, angular = self.sim.link_state(request.link_name, request.reference_frame)
            response = GetLinkStateResponse(success=True, status_message="GetLinkState: got state")
            state = response.link_state
            state.link_name, state.reference_frame = request.link_name, request.reference_frame
            state.pose, state.twist = _pose_to_message(pose), _twist_message(linear, angular)
            return response
        return self._guarded(GetLinkStateResponse, get)


def _refused(response_type, error: BridgeError):
    """A service's answer to a request refused with ``error``: success false and its one line."""
    rospy.logerr(str(error))
    return response_type(success=False, status_message=str(error))


def _inject_namespace(model, namespace: str):
    """spawn_urdf_model adds <robotNamespace> to every plugin that lacks one, sensor plugins included."""
    sensor_plugins = [plugin for _, sensor in model.sensors() for plugin in sensor.findall("plugin")]
    for element in model.plugins + sensor_plugins:
        if element.find("robotNamespace") is None:
            ElementTree.SubElement(element, "robotNamespace").text = namespace
