"""core/names.py: each plugin's <robotNamespace> default as upstream's plugins resolve it, tf frames, tf_prefix."""
import pytest
from mbot_sim_bridge.core import names
from mbot_sim_bridge.core.parameters import Parameters
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS

# Gazebo file name -> (absent, empty, given) for a model called "bot"; from the plugins' sources.
EXPECTED = dict([
    ("libgazebo_ros_diff_drive.so", ("bot", "bot", "r1")),
    ("libgazebo_ros_joint_state_publisher.so", ("bot", "bot", "r1")),
    ("libgazebo_ros_control.so", ("bot", "bot", "r1")),
    ("libgazebo_ros_laser.so", ("/", "bot", "r1")),
    ("libgazebo_ros_gpu_laser.so", ("/", "bot", "r1")),
    ("libgazebo_ros_depth_camera.so", ("/", "bot", "r1")),
    ("libgazebo_ros_camera.so", ("/", "bot", "r1")),
    ("libgazebo_ros_openni_kinect.so", ("/", "bot", "r1")),
    ("libgazebo_ros_imu.so", ("/", "/", "r1")),
    ("libgazebo_ros_p3d.so", ("/", "/", "r1")),
    ("libgazebo_ros_imu_sensor.so", ("/bot", "/", "r1")),
    ("libgazebo_ros_planar_move.so", ("/", "/", "r1")),
    ("libgazebo_ros_skid_steer_drive.so", ("/", "/", "r1")),
    ("libgazebo_ros_tricycle_drive.so", ("bot", "bot", "r1")),
    ("libgazebo_ros_multicamera.so", ("/", "bot", "r1")),
    ("libgazebo_ros_block_laser.so", ("/", "/", "r1")),
    ("libgazebo_ros_f3d.so", ("/", "/", "r1")),
    ("libgazebo_ros_ft_sensor.so", ("/", "/", "r1")),
    ("libgazebo_ros_force.so", ("/", "/", "r1")),
    ("libgazebo_ros_vacuum_gripper.so", ("/", "/", "r1")),
    # hector_gazebo_plugins (melodic-devel) and velodyne_simulator (1.0.13): NodeHandle(tag or "" / "/").
    ("libhector_gazebo_ros_imu.so", ("/", "/", "r1")),
    ("libhector_gazebo_ros_gps.so", ("/", "/", "r1")),
    ("libhector_gazebo_ros_magnetic.so", ("/", "/", "r1")),
    ("libgazebo_ros_velodyne_laser.so", ("/", "/", "r1")),
    ("libgazebo_ros_velodyne_gpu_laser.so", ("/", "/", "r1")),
    ("libgazebo_ros_range.so", ("/", "/", "r1")),
    ("libgazebo_ros_bumper.so", ("/", "/", "r1")),
    ("libhector_gazebo_ros_sonar.so", ("/", "/", "r1")),
    # roboticsgroup_upatras_gazebo_plugins: NodeHandle(tag or "").
    ("libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so", ("/", "/", "r1")),
    ("libroboticsgroup_gazebo_mimic_joint_plugin.so", ("/", "/", "r1")),
])


@pytest.mark.parametrize("filename", sorted(CORE_PLUGINS))
def test_every_plugin_with_a_namespace_tag_names_its_rule(filename):
    plugin_class = CORE_PLUGINS[filename]
    has_tag = any(param.tag == "robotNamespace" for param in plugin_class.PARAMS)
    assert (plugin_class.NAMESPACE_RULE is not None) == has_tag, filename
    if filename in EXPECTED:
        absent, empty, given = EXPECTED[filename]
        rule = plugin_class.NAMESPACE_RULE
        assert names.plugin_namespace(rule, None, "bot") == absent
        assert names.plugin_namespace(rule, "", "bot") == empty
        assert names.plugin_namespace(rule, "r1", "bot") == given
    else:
        assert not has_tag, f"{filename}: add its expected namespaces to this table"


def test_unknown_rule_is_refused():
    with pytest.raises(ValueError):
        names.plugin_namespace("nearest", None, "bot")


@pytest.mark.parametrize("frame, prefix, resolved", [("odom", "", "odom"), ("odom", "/r1/", "r1/odom"),
                                                      ("/odom", "r1", "odom"), ("base/link", "r1", "r1/base/link")])
def test_frames_resolve_as_tf_does(frame, prefix, resolved):
    assert names.resolve_frame(frame, prefix) == resolved


def test_tf_prefix_is_the_nearest_parameter_upwards():
    parameters = Parameters({"r1": {"tf_prefix": "robot1"}, "tf_prefix": "top"})
    assert names.tf_prefix(parameters, "/r1/sensors") == "robot1"
    assert names.tf_prefix(parameters, "/r2") == "top"
    assert names.tf_prefix(Parameters({}), "/r2") == ""
