"""gazebo_ros's ROS API (``libgazebo_ros_api_plugin.so``): the /gazebo/* services and model_states.

Handlers run in rospy's threads; each converts the request into Simulation calls that run in the loop
thread (``node.call_in_loop``) and the result back into a response.
"""
import math
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
from gazebo_msgs.srv import ApplyJointEffort, ApplyJointEffortResponse, JointRequest, JointRequestResponse
from gazebo_msgs.srv import SetLinkState, SetLinkStateResponse
from gazebo_msgs.srv import (GetJointProperties, GetJointPropertiesResponse, GetLinkProperties,
                             GetLinkPropertiesResponse, SetJointProperties, SetJointPropertiesResponse,
                             SetLinkProperties, SetLinkPropertiesResponse)
from gazebo_msgs.msg import LinkState, ModelState, ODEPhysics
from gazebo_msgs.srv import SetPhysicsProperties, SetPhysicsPropertiesResponse
from gazebo_msgs.srv import (DeleteLight, DeleteLightResponse, GetLightProperties, GetLightPropertiesResponse,
                             SetLightProperties, SetLightPropertiesResponse)
from std_msgs.msg import ColorRGBA
from geometry_msgs.msg import Pose as PoseMessage
from mbot_sim_msgs.srv import SaveWorld, StepSimulation, StepSimulationResponse
from geometry_msgs.msg import Twist
from std_srvs.srv import Empty, EmptyResponse

from .core.engine import check_model_name, check_state
from .core.entity_properties import LinkProperties
from .core.physics_properties import OdeConfig
from .core.errors import BridgeError, ModelError
from .core.geometry import Pose, compose, rotate
from .gazebo_paths import model_path
from .core.description.robot_model import parse_robot
from .core.description.sdf_spawn import read_spawned_model, spawned_pose
from .model_states import LinkStatesPublisher, ModelStatesPublisher
from .package_uris import resolve_package_uris
from .performance_metrics import PerformanceMetricsPublisher
from .physics_reconfigure import PhysicsReconfigure
from .plugins import namespace_complaint, ros_time
from .subscriptions import drain
from .world_saving import SaveWorldHandler

SPAWN_FRAME_NOT_FOUND = ("SpawnModel: reference reference_frame not found, did you forget to scope the link by model "
                         "name?")
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


def _colour(colour: ColorRGBA):
    return colour.r, colour.g, colour.b, colour.a


def _twist_vectors(twist: Twist):
    return ((twist.linear.x, twist.linear.y, twist.linear.z), (twist.angular.x, twist.angular.y, twist.angular.z))


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
        self.link_states = LinkStatesPublisher(self.sim)
        self.performance_metrics = PerformanceMetricsPublisher(self.sim)
        self.physics_reconfigure = PhysicsReconfigure(node)
        # As upstream's: the topics take the services' requests, and a refused one is only logged.
        self._subscribers = [
            rospy.Subscriber("~set_model_state", ModelState, lambda state: self._set_model_state(
                SetModelState._request_class(model_state=state))),
            rospy.Subscriber("~set_link_state", LinkState, lambda state: self._set_link_state(
                SetLinkState._request_class(link_state=state))),
        ]
        self._services = [
            rospy.Service("~spawn_urdf_model", SpawnModel, self._spawn_urdf_model),
            rospy.Service("~spawn_sdf_model", SpawnModel, self._spawn_sdf_model),
            rospy.Service("~delete_model", DeleteModel, self._delete_model),
            rospy.Service("~get_model_state", GetModelState, self._get_model_state),
            rospy.Service("~set_model_state", SetModelState, self._set_model_state),
            rospy.Service("~get_world_properties", GetWorldProperties, self._get_world_properties),
            rospy.Service("~get_physics_properties", GetPhysicsProperties, self._get_physics_properties),
            rospy.Service("~set_physics_properties", SetPhysicsProperties, self._set_physics_properties),
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
            rospy.Service("~apply_joint_effort", ApplyJointEffort, self._apply_joint_effort),
            rospy.Service("~clear_joint_forces", JointRequest, self._clear_joint_forces),
            rospy.Service("~set_link_state", SetLinkState, self._set_link_state),
            rospy.Service("~get_joint_properties", GetJointProperties, self._get_joint_properties),
            rospy.Service("~set_joint_properties", SetJointProperties, self._set_joint_properties),
            rospy.Service("~get_link_properties", GetLinkProperties, self._get_link_properties),
            rospy.Service("~set_link_properties", SetLinkProperties, self._set_link_properties),
            rospy.Service("~get_light_properties", GetLightProperties, self._get_light_properties),
            rospy.Service("~set_light_properties", SetLightProperties, self._set_light_properties),
            rospy.Service("~delete_light", DeleteLight, self._delete_light),
            # The bridge's own; the loaded world's description gives its name, scene and other elements.
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
        complaint = namespace_complaint(request.robot_namespace)
        if complaint:
            raise ModelError(f"SpawnModel: robot_namespace '{request.robot_namespace}' {complaint}; nothing was "
                             "spawned")
        requested = _pose_from_message(request.initial_pose)
        # Checked as sent too: composed with the reference frame, 1e300 would turn inf and NaN and be named so.
        check_state(f"SpawnModel: model '{request.model_name}'", requested)
        pose = compose(self.sim.reference_pose(request.reference_frame, SPAWN_FRAME_NOT_FOUND), requested)
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
        name = request.model_name
        try:
            pose = self.node.call_in_loop(lambda: self._new_model_pose(request))
            # Read in this service thread, not the loop's: a model of 48 MB stopped /clock for minutes.
            description = read_spawned_model(resolve_package_uris(request.model_xml), name, pose,
                                             request.robot_namespace, model_path())
        except BridgeError as error:
            return _refused(SpawnModelResponse, error)

        def spawn():
            if name not in self.sim.add_world(description, request.robot_namespace or "/"):
                raise ModelError(f"model '{name}' has no collision geometry; nothing to simulate")
            placed = spawned_pose(description, name)
            rospy.loginfo(f"spawned SDF model '{name}' at {tuple(round(v, 3) for v in placed.position)}")
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
    def _get_model_state(self, request):
        def get():
            pose, linear, angular = self.sim.model_state(request.model_name, request.relative_entity_name)
            response = GetModelStateResponse(pose=_pose_to_message(pose), twist=_twist_message(linear, angular),
                                             success=True, status_message="GetModelState: got properties")
            response.header.stamp = ros_time(self.sim.sim_time)
            response.header.frame_id = request.relative_entity_name
            return response
        return self._guarded(GetModelStateResponse, get)

    def _set_model_state(self, request):
        state = request.model_state

        def set_state():
            if state.model_name not in self.sim.model_names():
                raise ModelError("SetModelState: model does not exist")
            reference = self.sim.reference_pose(state.reference_frame,
                                                 "SetModelState: specified reference frame entity does not exist")
            requested, (linear, angular) = _pose_from_message(state.pose), _twist_vectors(state.twist)
            # Checked as sent too: transformed, 1e300 would turn inf and NaN, and on other axes.
            check_state(f"SetModelState: model '{state.model_name}'", requested, linear, angular)
            pose = compose(reference, requested)
            linear, angular = rotate(reference.orientation, linear), rotate(reference.orientation, angular)
            self.sim.set_model_state(state.model_name, pose, linear, angular)
            return SetModelStateResponse(success=True, status_message="SetModelState: set model state done")
        return self._guarded(SetModelStateResponse, set_state)

    def _set_link_state(self, request):
        state = request.link_state

        def set_state():
            self.sim.set_link_state(state.link_name, state.reference_frame, _pose_from_message(state.pose),
                                    *_twist_vectors(state.twist))
            return SetLinkStateResponse(success=True, status_message="SetLinkState: success")
        return self._guarded(SetLinkStateResponse, set_state)

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
                                              rendering_enabled=True, success=True,
                                              status_message="GetWorldProperties: got properties")
        return self._guarded(GetWorldPropertiesResponse, get)

    def _get_physics_properties(self, _request):
        def get():
            physics = self.sim.engine.physics
            response = GetPhysicsPropertiesResponse(time_step=physics.max_step_size, pause=self.sim.paused,
                                                    max_update_rate=physics.real_time_update_rate,
                                                    ode_config=ODEPhysics(**self.sim.ode_config()._asdict()),
                                                    success=True, status_message="GetPhysicsProperties: got properties")
            response.gravity.x, response.gravity.y, response.gravity.z = physics.gravity
            return response
        return self._guarded(GetPhysicsPropertiesResponse, get)

    def _set_physics_properties(self, request):
        def set_physics():
            gravity = (request.gravity.x, request.gravity.y, request.gravity.z)
            ode = OdeConfig(**{field: getattr(request.ode_config, field) for field in OdeConfig._fields})
            self.sim.set_physics(request.time_step, request.max_update_rate, gravity, ode)
            self.node.physics_changed()
            return SetPhysicsPropertiesResponse(success=True, status_message="physics engine updated")
        return self._guarded(SetPhysicsPropertiesResponse, set_physics)

    # -- joints --------------------------------------------------------------------------------------------------
    def _apply_joint_effort(self, request):
        def apply():
            self.sim.apply_joint_effort(request.joint_name, request.effort, request.start_time.to_sec(),
                                        request.duration.to_sec())
            return ApplyJointEffortResponse(success=True, status_message="ApplyJointEffort: effort set")
        return self._guarded(ApplyJointEffortResponse, apply)

    def _clear_joint_forces(self, request):
        self.node.call_in_loop(lambda: self.sim.joint_efforts.clear_named(request.joint_name))
        return JointRequestResponse()

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


    # -- link and joint properties ---------------------------------------------------------------------------------
    def _get_joint_properties(self, request):
        def get():
            properties = self.sim.joint_properties(request.joint_name)
            return GetJointPropertiesResponse(**properties._asdict(), success=True,
                                              status_message="GetJointProperties: got properties")
        return self._guarded(GetJointPropertiesResponse, get)

    def _set_joint_properties(self, request):
        def set_properties():
            self.sim.set_joint_properties(request.joint_name, request.ode_joint_config)
            return SetJointPropertiesResponse(success=True, status_message="SetJointProperties: properties set")
        return self._guarded(SetJointPropertiesResponse, set_properties)

    def _get_link_properties(self, request):
        def get():
            properties = self.sim.link_properties(request.link_name)
            return GetLinkPropertiesResponse(**properties._replace(com=_pose_to_message(properties.com))._asdict(),
                                             success=True, status_message="GetLinkProperties: got properties")
        return self._guarded(GetLinkPropertiesResponse, get)

    def _set_link_properties(self, request):
        def set_properties():
            fields = {field: getattr(request, field) for field in LinkProperties._fields}
            self.sim.set_link_properties(request.link_name, LinkProperties(**{
                **fields, "com": _pose_from_message(request.com)}))
            return SetLinkPropertiesResponse(success=True, status_message="SetLinkProperties: properties set")
        return self._guarded(SetLinkPropertiesResponse, set_properties)

    # -- lights (kept, not rendered: core/lights.py) -------------------------------------------------------------------
    def _get_light_properties(self, request):
        def get():
            light = self.sim.lights.get(request.light_name)
            constant, linear, quadratic = light.attenuation
            # Upstream answers success with no status message.
            return GetLightPropertiesResponse(diffuse=ColorRGBA(*light.diffuse), attenuation_constant=constant,
                                              attenuation_linear=linear, attenuation_quadratic=quadratic,
                                              success=True)
        return self._guarded(GetLightPropertiesResponse, get)

    def _set_light_properties(self, request):
        def set_properties():
            direction = request.direction
            self.sim.lights.set(request.light_name, request.cast_shadows, _colour(request.diffuse),
                                _colour(request.specular), (request.attenuation_constant, request.attenuation_linear,
                                                           request.attenuation_quadratic),
                                (direction.x, direction.y, direction.z), _pose_from_message(request.pose))
            return SetLightPropertiesResponse(success=True)
        return self._guarded(SetLightPropertiesResponse, set_properties)

    def _delete_light(self, request):
        def delete():
            self.sim.lights.delete(request.light_name)
            return DeleteLightResponse(success=True,
                                       status_message=f"DeleteLight: {request.light_name} successfully deleted")
        return self._guarded(DeleteLightResponse, delete)


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
