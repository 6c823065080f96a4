"""NaN, inf and huge values on every input of the drives and sensors of published robots (planar move, skid steer,
tricycle, hector IMU/GPS/magnetometer, range, sonar, bumper, Velodyne, block laser, multicamera, ft sensor, f3d,
mimic joints, grasp fix): each value is refused with one line naming the tag, or runs without an exception, and a
robot two metres away does not move by 1 mm. Every edit is checked to have changed the robot: a tag the robot lacks
is added to the plugins that read it."""
import math
import os
import re
import warnings

import pytest
from sensor_fixtures import box, world_simulation
from plugin_robots import (BUMPER_LUMPED_COLLISION, BUMPER_ROBOT, HECTOR_ROBOT, HECTOR_SONAR_PLUGIN, HOLONOMIC_XACRO,
                           MIMIC_GRIPPER, MIMIC_PLUGIN_BLOCK, MOBILE_TEST_ROBOTS, RANGE_PLUGIN, SKID_XACRO, SONAR_ROBOT,
                           SONAR_SENSOR, STEREO_XACRO, TRICYCLE_XACRO, VELODYNE_STAND)

from mbot_sim_bridge.core.errors import BridgeError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.parameters import Parameters
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.robot_description import expand_xacro

VLP16_MACRO = os.path.abspath(os.path.join(MOBILE_TEST_ROBOTS, "urdf", "VLP-16.urdf.xacro"))
BAD_VALUES = (math.nan, math.inf, -math.inf, 1e308, -1e308)
BAD_TEXTS = ("nan", "inf", "-inf", "1e308", "-1e308", "1e-308")
# For the tags of the later plugins: one of each kind (the parser refuses nan and inf alike; the sign of a huge
# value is read the same way), so the suite stays within its time.
TAG_TEXTS = ("nan", "-inf", "1e308", "1e-308")
BYSTANDER = """<robot name="crate"><link name="crate"><inertial><mass value="1"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision></link></robot>"""


def with_tag(urdf, tag, value, plugin_files=()):
    """``urdf`` with every ``<tag>`` set to ``value``; where it has none, the tag added to the plugins of
    ``plugin_files``. Fails when nothing changed, so that no case runs the unmodified robot."""
    edited, count = re.subn(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{value}</{tag}>", urdf)
    if count == 0:
        for filename in plugin_files:
            edited, added = re.subn(f'(<plugin [^>]*filename="{re.escape(filename)}"[^>]*>)',
                                    rf"\1<{tag}>{value}</{tag}>", edited)
            count += added
    assert count > 0 and edited != urdf, f"<{tag}> is in none of {plugin_files or 'the robot'}: the edit did nothing"
    return edited


def assert_refused_or_harmless(outcome, tag, text):
    """A refusal is one line naming the tag and the value (as written or as the number read); a run leaves the
    bystander within 1 mm."""
    if isinstance(outcome, str):
        assert "\n" not in outcome and f"{tag}>" in outcome, outcome
        assert text in outcome or f"{float(text):g}" in outcome, outcome
    else:
        assert outcome < 1e-3


def run(tmp_path, urdf, command=None, steps=300, parameters=None):
    """Spawn ``urdf`` beside a dynamic crate (with ``parameters`` on the parameter server), send ``command`` to its
    drive, step: the crate's displacement, or the refusal's text when the spawn was refused (ConfigError/ModelError)."""
    sim = world_simulation(tmp_path, box("wall", (1.2, 0.0, 0.5), (0.1, 4.0, 1.0)))
    if parameters is not None:
        sim.parameters = parameters
    try:
        sim.spawn_robot(parse_robot(BYSTANDER, "model 'crate'"), "crate", pose_from_xyz_rpy((2, 2, 0.15), (0, 0, 0)))
        sim.step(100)
        start = sim.engine.model_pose("crate").position
        try:
            spawned = sim.spawn_robot(parse_robot(urdf, "model 'robot'"), "robot")
        except BridgeError as refusal:
            return str(refusal)
        if command is not None:
            for plugin in spawned.plugins:
                if hasattr(plugin, "set_command"):
                    command(plugin)
        plugins = list(spawned.plugins)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # an overflow inside a plugin would make it raise
            sim.step(steps)
        assert spawned.plugins == plugins  # a plugin that raised would have been dropped
        return math.dist(start, sim.engine.model_pose("crate").position)
    finally:
        sim.close()


@pytest.fixture(scope="module")
def velodyne_urdf(tmp_path_factory):
    path = tmp_path_factory.mktemp("velodyne") / "stand.urdf.xacro"
    stand = VELODYNE_STAND.format(macro=VLP16_MACRO, noise=0.008, organize="true")
    # A tenth of the samples: a refusal does not depend on them, and update_rate 1e308 sweeps at every step.
    assert 'samples="440"' in stand
    path.write_text(stand.replace('samples="440"', 'samples="44"'))
    return expand_xacro(str(path))


VELODYNE_FILES = ("libgazebo_ros_velodyne_laser.so",)
VELODYNE_TAGS = ["min_range", "max_range", "min_intensity", "gaussianNoise", "update_rate", "samples", "max_angle"]


@pytest.mark.parametrize("text", BAD_TEXTS)
@pytest.mark.parametrize("tag", VELODYNE_TAGS)
def test_velodyne_tags(tmp_path, velodyne_urdf, tag, text):
    urdf = with_tag(velodyne_urdf, tag, text, VELODYNE_FILES)
    assert_refused_or_harmless(run(tmp_path, urdf), tag, text)


@pytest.fixture(scope="module")
def drives():
    return {"planar": expand_xacro(HOLONOMIC_XACRO),
            "skid": expand_xacro(SKID_XACRO)}


DRIVE_TAGS = [("skid", "torque"), ("skid", "wheelDiameter"), ("skid", "wheelSeparation"), ("skid", "updateRate"),
              ("skid", "covariance_yaw"), ("planar", "odometryRate"), ("planar", "cmdTimeout")]


@pytest.mark.parametrize("value", BAD_VALUES)
@pytest.mark.parametrize("drive, axis", [("planar", 0), ("planar", 1), ("planar", 2), ("skid", 0), ("skid", 1)])
def test_drive_commands(tmp_path, drives, drive, axis, value):
    command = [0.0] * (3 if drive == "planar" else 2)
    command[axis] = value
    moved = run(tmp_path, drives[drive], lambda plugin: plugin.set_command(*command))
    assert moved < 1e-3


@pytest.mark.parametrize("text", BAD_TEXTS)
@pytest.mark.parametrize("drive, tag", DRIVE_TAGS)
def test_drive_tags(tmp_path, drives, drive, tag, text):
    urdf = with_tag(drives[drive], tag, text)
    command = (lambda plugin: plugin.set_command(0.5, 0.0, 0.5)) if drive == "planar" else (
        lambda plugin: plugin.set_command(0.5, 0.5))
    assert_refused_or_harmless(run(tmp_path, urdf, command), tag, text)


SONARS = (SONAR_SENSOR.format(name="front", plugin=RANGE_PLUGIN.format(radiation="ultrasound", noise=0))
          + SONAR_SENSOR.format(name="rear", plugin=HECTOR_SONAR_PLUGIN.format(noise=0)))
SENSOR_ROBOTS = {"hector": HECTOR_ROBOT.format(heading=0, imu="", gps=""), "sonar": SONAR_ROBOT.format(sensors=SONARS),
                 "bumper": BUMPER_ROBOT.format(collision=BUMPER_LUMPED_COLLISION)}
# Where a tag the robot lacks goes: the plugins that read it.
SENSOR_FILES = {"hector": ("libhector_gazebo_ros_imu.so", "libhector_gazebo_ros_gps.so",
                           "libhector_gazebo_ros_magnetic.so"),
                "sonar": ("libgazebo_ros_range.so", "libhector_gazebo_ros_sonar.so"), "bumper": ()}
SENSOR_TAGS = [("hector", tag) for tag in ("updateRate", "gaussianNoise", "magnitude", "inclination", "declination",
                                           "referenceHeading", "referenceLatitude", "referenceAltitude", "accelDrift",
                                           "rateDriftFrequency", "driftFrequency", "scaleError", "offset",
                                           "velocityGaussianNoise", "yawDrift")] + [
    ("sonar", tag) for tag in ("fov", "gaussianNoise", "updateRate", "min", "max", "samples")] + [
    ("bumper", "update_rate")]
VECTOR_TAGS = {"accelDrift", "rateDriftFrequency", "driftFrequency", "scaleError", "offset",
               "velocityGaussianNoise"}


@pytest.mark.parametrize("text", BAD_TEXTS)
@pytest.mark.parametrize("robot, tag", SENSOR_TAGS)
def test_sensor_tags(tmp_path, robot, tag, text):
    value = " ".join([text] * 3) if tag in VECTOR_TAGS else text
    urdf = with_tag(SENSOR_ROBOTS[robot], tag, value, SENSOR_FILES[robot])
    assert_refused_or_harmless(run(tmp_path, urdf), tag, text)


@pytest.fixture(scope="module")
def tricycle():
    return expand_xacro(TRICYCLE_XACRO, odometry_source="encoder")


@pytest.mark.parametrize("value", BAD_VALUES)
@pytest.mark.parametrize("axis", [0, 1])
def test_tricycle_commands(tmp_path, tricycle, axis, value):
    command = [0.3, 0.2]
    command[axis] = value
    assert run(tmp_path, tricycle, lambda plugin: plugin.set_command(*command)) < 1e-3


TRICYCLE_FILES = ("libgazebo_ros_tricycle_drive.so",)
TRICYCLE_TAGS = ["actuatedWheelDiameter", "encoderWheelDiameter", "encoderWheelSeparation", "wheelTorque",
                 "updateRate", "wheelAcceleration", "wheelSpeedTolerance", "steeringSpeed", "steeringAngleTolerance",
                 "gaussianNoise", "samples", "min", "max"]


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", TRICYCLE_TAGS)
def test_tricycle_and_block_laser_tags(tmp_path, tricycle, tag, text):
    urdf = with_tag(tricycle, tag, text, TRICYCLE_FILES)
    assert_refused_or_harmless(run(tmp_path, urdf, lambda plugin: plugin.set_command(0.3, 0.2)), tag, text)


@pytest.fixture(scope="module")
def stereo_head():
    # Images of 32 x 24: no check here reads a pixel, and 50 Hz renders both cameras 15 times in a run.
    return expand_xacro(STEREO_XACRO, rate="50", width="32", height="24")


STEREO_FILES = ("libgazebo_ros_ft_sensor.so",)
STEREO_TAGS = ["horizontal_fov", "width", "near", "far", "hackBaseline", "updateRate", "gaussianNoise", "pose"]


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", STEREO_TAGS)
def test_stereo_head_tags(tmp_path, stereo_head, tag, text):
    """The multicamera's, the ft sensor's (gaussianNoise, updateRate) and the f3d's inputs."""
    value = " ".join([text] * 6) if tag == "pose" else text
    urdf = with_tag(stereo_head, tag, value, STEREO_FILES)
    assert_refused_or_harmless(run(tmp_path, urdf), tag, text)


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", ["multiplier", "offset", "sensitiveness", "maxEffort"])
def test_mimic_tags(tmp_path, tag, text):
    plugin = MIMIC_PLUGIN_BLOCK.format(extra=f"<hasPID/><{tag}>{text}</{tag}>" if tag == "maxEffort"
                                       else f"<{tag}>{text}</{tag}>")
    urdf = MIMIC_GRIPPER.format(mimic="", plugin=plugin.replace("<multiplier>-1</multiplier>", "")
                          .replace("<offset>0.002</offset>", "") if tag in ("multiplier", "offset") else plugin)
    assert f"<{tag}>{text}</{tag}>" in urdf
    # maxEffort clamps the PID's effort: the PID needs gains, else the spawn is refused for want of them.
    gains = Parameters({"gazebo_ros_control": {"pid_gains": {"right_finger_joint": {"p": 2000.0, "d": 20.0}}}})
    assert_refused_or_harmless(run(tmp_path, urdf, parameters=gains), tag, text)


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("attribute", ["multiplier", "offset"])
def test_urdf_mimic_attributes(tmp_path, attribute, text):
    mimic = f'<mimic joint="left_finger_joint" {attribute}="{text}"/>'
    assert_refused_or_harmless(run(tmp_path, MIMIC_GRIPPER.format(mimic=mimic, plugin="")), attribute, text)


GRASP_FIX_TAGS = ["forces_angle_tolerance", "update_rate", "max_grip_count", "grip_count_threshold",
                  "release_tolerance", "disable_collisions_on_attach"]
GRASP_FIX_BLOCK = """<gazebo><plugin name="grasp_fix" filename="libgazebo_grasp_fix.so"><{tag}>{text}</{tag}>
  <arm><arm_name>hand</arm_name><palm_link>palm</palm_link><gripper_link>left_finger</gripper_link>
    <gripper_link>right_finger</gripper_link></arm></plugin></gazebo>"""


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", GRASP_FIX_TAGS)
def test_grasp_fix_tags(tmp_path, tag, text):
    urdf = MIMIC_GRIPPER.format(mimic="", plugin=GRASP_FIX_BLOCK.format(tag=tag, text=text))
    assert_refused_or_harmless(run(tmp_path, urdf), tag, text)


def test_every_tag_edit_changes_the_robot(velodyne_urdf, drives, tricycle, stereo_head):
    """The class of case that ran the unmodified robot and passed cannot come back: every parametrized edit of
    this module puts the bad value into the robot's text."""
    cases = ([(velodyne_urdf, tag, VELODYNE_FILES) for tag in VELODYNE_TAGS]
             + [(drives[drive], tag, ()) for drive, tag in DRIVE_TAGS]
             + [(SENSOR_ROBOTS[robot], tag, SENSOR_FILES[robot]) for robot, tag in SENSOR_TAGS]
             + [(tricycle, tag, TRICYCLE_FILES) for tag in TRICYCLE_TAGS]
             + [(stereo_head, tag, STEREO_FILES) for tag in STEREO_TAGS])
    for urdf, tag, files in cases:
        assert f"<{tag}>-7.25</{tag}>" in with_tag(urdf, tag, "-7.25", files)
