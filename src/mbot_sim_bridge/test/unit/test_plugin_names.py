"""The names the ROS plugins advertise (plugins/__init__.py, PluginTopics): two plugins that would advertise one
service, or one topic as two types, leave the second out with one warning naming both and the name, and the world
or model goes on; a name that is not a legal ROS name, or a robot namespace rospy cannot take, refuses the plugin
with one line. Built with the ROS plugin classes, without a master: rospy keeps its registrations locally."""
import logging
import os

import pytest
import rosgraph.names
import rospy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from std_srvs.srv import Empty, EmptyResponse

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.errors import BridgeError, ConfigError
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge import plugins
from mbot_sim_bridge.plugins import namespace_complaint
from mbot_sim_bridge.plugins.registry import REGISTRY

WORLD = """<sdf version="1.6"><world name="w">{plugins}</world></sdf>"""
ATTACHER = "<plugin name='{name}' filename='libgazebo_ros_link_attacher.so'/>"
# One link with a collision and the plugin blocks given.
ROBOT = """<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
  </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <gazebo>{plugins}</gazebo>
</robot>"""
VACUUM = """<plugin name="{name}" filename="libgazebo_ros_vacuum_gripper.so">
  <robotNamespace>{namespace}</robotNamespace><bodyName>base</bodyName><topicName>grasping</topicName></plugin>"""
P3D = """<plugin name="{name}" filename="libgazebo_ros_p3d.so"><bodyName>base</bodyName>
  <topicName>{topic}</topicName><robotNamespace>{namespace}</robotNamespace></plugin>"""
IMU = """<plugin name="{name}" filename="libgazebo_ros_imu.so"><bodyName>base</bodyName>
  <topicName>{topic}</topicName><serviceName>imu_service</serviceName></plugin>"""
FORCE = """<plugin name="{name}" filename="libgazebo_ros_force.so"><bodyName>base</bodyName>
  <topicName>{topic}</topicName><robotNamespace>{namespace}</robotNamespace></plugin>"""

# The fuzzing below is seeded (derandomize) and draws a sample in the suite, more with MBOT_FULL_SWEEP=1.
FULL_SWEEP = bool(os.environ.get("MBOT_FULL_SWEEP"))
FUZZ = settings(derandomize=True, deadline=None, database=None, max_examples=300 if FULL_SWEEP else 25,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
# Few names, so that draws clash often: the vacuum gripper's topic and services, the IMU's service, the shipped
# robots' topics, and names ROS cannot take (no private ones: rospy makes them only in a node).
TOPICS = ("grasping", "/shared", "on", "imu_service", "cmd_vel", "/clock", "a b", "/../up", "x//y", "-")
NAMESPACES = ("", "/", "vac1", "/vac1", "~priv", "a b", "/../..", "-")
PLUGIN_BLOCKS = (VACUUM, P3D, IMU, FORCE)


@pytest.fixture
def sim(tmp_path):
    path = tmp_path / "two_attachers.world"
    path.write_text(WORLD.format(plugins=""))
    with Simulation(parse_world(str(path)), REGISTRY) as simulation:
        yield simulation


def spawn(sim, name, *plugins):
    return sim.spawn_robot(parse_robot(ROBOT.format(plugins="".join(plugins)), f"model '{name}'"), name)


def left_out_lines(caplog):
    return [record.getMessage() for record in caplog.records
            if record.levelno == logging.WARNING and "is left out" in record.getMessage()]


def test_two_link_attachers_in_a_world_keep_the_first_and_the_world_goes_on(tmp_path, caplog):
    path = tmp_path / "two_attachers.world"
    path.write_text(WORLD.format(plugins=ATTACHER.format(name="first") + ATTACHER.format(name="second")))
    with Simulation(parse_world(str(path)), REGISTRY) as simulation:
        first, = simulation.world_plugins.plugins
        assert first.element.get("name") == "first"
        line, = left_out_lines(caplog)
        assert "plugin 'second' (libgazebo_ros_link_attacher.so) of world 'w'" in line
        assert "plugin 'first' (libgazebo_ros_link_attacher.so) of world 'w'" in line
        assert "'/link_attacher_node/attach'" in line and "\n" not in line
        simulation.step(10)
    # Closed with the world, the name is free again: a world built afterwards has its attacher.
    with Simulation(parse_world(str(path)), REGISTRY) as simulation:
        assert len(simulation.world_plugins.plugins) == 1


def test_a_second_vacuum_gripper_in_one_namespace_is_left_out_and_the_model_spawns(sim, caplog):
    first = spawn(sim, "g1", VACUUM.format(name="vacuum", namespace="vac1"))
    second = spawn(sim, "g2", VACUUM.format(name="vacuum", namespace="vac1"),
                   P3D.format(name="p3d", topic="g2_pose", namespace="/"))
    assert [type(plugin).__name__ for plugin in second.plugins] == ["GazeboRosP3D"]
    line, = left_out_lines(caplog)
    assert "plugin 'vacuum' (libgazebo_ros_vacuum_gripper.so) of model 'g2' is left out" in line
    assert "'/vac1/on'" in line and "of model 'g1' already advertises" in line
    assert len(first.plugins) == 1 and "g2" in sim.model_names()
    sim.step(10)
    # Deleted, the first gives its names back.
    sim.delete("g1")
    third = spawn(sim, "g3", VACUUM.format(name="vacuum", namespace="vac1"))
    assert len(third.plugins) == 1


def test_one_topic_as_two_types_leaves_the_second_out_and_one_type_is_shared(sim, caplog):
    spawn(sim, "a", P3D.format(name="pose", topic="/shared", namespace="/"))
    shared = spawn(sim, "b", P3D.format(name="pose", topic="/shared", namespace="/"))
    assert len(shared.plugins) == 1 and not left_out_lines(caplog)  # two Odometry publishers: as Gazebo's
    imu = spawn(sim, "c", IMU.format(name="imu", topic="/shared"))
    assert imu.plugins == []
    line, = left_out_lines(caplog)
    assert "plugin 'imu' (libgazebo_ros_imu.so) of model 'c' is left out: it would publish '/shared' as " \
           "sensor_msgs/Imu, which plugin 'pose' (libgazebo_ros_p3d.so) of model 'a' already publishes as " \
           "nav_msgs/Odometry" in line


def test_a_name_the_simulator_itself_holds_leaves_the_plugin_out(sim, caplog):
    service = rospy.Service("/taken/imu_service", Empty, lambda request: EmptyResponse())
    try:
        spawned = spawn(sim, "m", IMU.format(name="imu", topic="imu").replace(
            "<serviceName>imu_service", "<serviceName>/taken/imu_service"))
    finally:
        service.shutdown()
    assert spawned.plugins == []
    line, = left_out_lines(caplog)
    assert "'/taken/imu_service', which the simulator itself already advertises" in line


@pytest.mark.parametrize("namespace", ["~priv", "a b", "/../..", "//a", "1robot", "a-b"])
def test_a_robot_namespace_from_a_plugin_tag_that_ros_cannot_take_refuses_the_spawn(sim, namespace):
    with pytest.raises(ConfigError) as refused:
        spawn(sim, "m", P3D.format(name="p3d", topic="pose", namespace=namespace))
    message = str(refused.value)
    assert f"<robotNamespace> '{namespace}'" in message and "GazeboRosP3D" in message and "\n" not in message
    assert "m" not in sim.model_names()


def test_a_topic_name_that_is_not_a_ros_name_refuses_the_spawn(sim):
    with pytest.raises(ConfigError) as refused:
        spawn(sim, "m", P3D.format(name="p3d", topic="a b", namespace="/"))
    assert "plugin 'p3d' (libgazebo_ros_p3d.so) of model 'm': publisher name '/a b' is not a legal ROS name" in \
        str(refused.value)
    # Refused whole: the name it held before the bad one (none here) and the model are gone.
    assert "m" not in sim.model_names()
    assert len(spawn(sim, "m", P3D.format(name="p3d", topic="a_b", namespace="/")).plugins) == 1


def test_a_spawn_refused_half_way_gives_back_the_names_its_plugins_took(sim):
    with pytest.raises(ConfigError):
        spawn(sim, "m", VACUUM.format(name="vacuum", namespace="vac1"), P3D.format(name="p3d", topic="a b",
                                                                                     namespace="/"))
    assert len(spawn(sim, "m", VACUUM.format(name="vacuum", namespace="vac1")).plugins) == 1


@pytest.mark.parametrize("namespace", ["", "/", "/good", "good", "a/b", "/a_1/b2", "/a/"])
def test_legal_namespaces_are_taken(namespace):
    assert namespace_complaint(namespace) is None


@pytest.mark.parametrize("namespace, expected", [
    ("~priv", "is a private name"), ("a b", "is not a legal ROS name"), ("/../..", "is not a legal ROS name"),
    ("//a", "no '//'"), ("a\nb", "is not a legal ROS name")])
def test_namespaces_ros_cannot_take_are_named(namespace, expected):
    complaint = namespace_complaint(namespace)
    assert expected in complaint and "\n" not in complaint


@st.composite
def clashing_models(draw):
    """Models of one to three of the plugins above, each with a topic and namespace drawn from few names (or any
    short text)."""
    namespaces = st.sampled_from(NAMESPACES) | st.text(alphabet="ab/~ .-_1", max_size=5)
    models = []
    for _ in range(draw(st.integers(1, 4))):
        blocks = draw(st.lists(st.sampled_from(PLUGIN_BLOCKS), min_size=1, max_size=3))
        models.append([block.format(name=f"p{index}", topic=draw(st.sampled_from(TOPICS)),
                                    namespace=draw(namespaces).replace("<", ""))
                       for index, block in enumerate(blocks)])
    return models


@FUZZ
@given(models=clashing_models())
def test_clashing_and_illegal_names_fuzzed(sim, caplog, models):
    """Every spawn loads, refused with one line, or leaves plugins out with one line each naming both; the loop
    steps; and once the models are deleted no name stays held (a refused or left-out plugin gives its back)."""
    caplog.clear()
    spawned = []
    for index, blocks in enumerate(models):
        name = f"m{index}"
        try:
            spawned.append(spawn(sim, name, *blocks).name)
        except BridgeError as error:
            assert "\n" not in str(error) and name not in sim.model_names()
    for line in left_out_lines(caplog):
        assert line.count("plugin '") == 2 and "\n" not in line, line
    sim.step(5)
    for name in spawned:
        sim.delete(name)
    assert plugins._HOLDERS == {}


@FUZZ
@given(namespace=st.text(max_size=8))
def test_a_namespace_taken_makes_legal_names(namespace):
    """A namespace namespace_complaint lets through gives every plugin topic under it a name ROS takes."""
    if namespace_complaint(namespace) is None:
        resolved = rospy.resolve_name(rosgraph.names.ns_join(namespace or "/", "joint_states"))
        assert rosgraph.names.is_legal_name(resolved) and resolved.startswith("/"), resolved
