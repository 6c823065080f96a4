"""NaN, inf and huge values on every input of the drives and sensors of published robots (planar move, skid steer,
tricycle, hector IMU/GPS/magnetometer, range, sonar, bumper, Velodyne, block laser, multicamera, ft sensor, f3d, mimic
joints): each value is refused with one line, or runs without an exception, and a robot two metres away does not
move by 1 mm."""
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


def run(tmp_path, urdf, command=None, steps=300):
    """Spawn ``urdf`` beside a dynamic crate, send ``command`` to its drive, step: the crate's displacement, or
    None when the spawn was refused (ConfigError/ModelError with one line)."""
    sim = world_simulation(tmp_path, box("wall", (1.2, 0.0, 0.5), (0.1, 4.0, 1.0)))
    try:
        sim.spawn_robot(parse_robot(BYSTANDER, "model 'crate'"), "crate", pose_from_xyz_rpy((2, 2, 0.15), (0, 0, 0)))
        sim.step(100)
        start = sim.engine.model_pose("crate").position
        try:
            spawned = sim.spawn_robot(parse_robot(urdf, "model 'robot'"), "robot")
        except BridgeError:
            return None
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
    path.write_text(VELODYNE_STAND.format(macro=VLP16_MACRO, noise=0.008, organize="true"))
    return expand_xacro(str(path))


@pytest.mark.parametrize("text", BAD_TEXTS)
@pytest.mark.parametrize("tag", ["min_range", "max_range", "min_intensity", "gaussianNoise", "update_rate", "samples",
                                 "max_angle"])
def test_velodyne_tags(tmp_path, velodyne_urdf, tag, text):
    urdf = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{text}</{tag}>", velodyne_urdf)
    moved = run(tmp_path, urdf)
    assert moved is None or moved < 1e-3


@pytest.fixture(scope="module")
def drives():
    return {"planar": expand_xacro(HOLONOMIC_XACRO),
            "skid": expand_xacro(SKID_XACRO)}


@pytest.mark.parametrize("value", BAD_VALUES)
@pytest.mark.parametrize("drive, axis", [("planar", 0), ("planar", 1), ("planar", 2), ("skid", 0), ("skid", 1)])
def test_drive_commands(tmp_path, drives, drive, axis, value):
    command = [0.0] * (3 if drive == "planar" else 2)
    command[axis] = value
    moved = run(tmp_path, drives[drive], lambda plugin: plugin.set_command(*command))
    assert moved < 1e-3


@pytest.mark.parametrize("text", BAD_TEXTS)
@pytest.mark.parametrize("drive, tag", [("skid", "torque"), ("skid", "wheelDiameter"), ("skid", "wheelSeparation"),
                                        ("skid", "updateRate"), ("skid", "covariance_yaw"),
                                        ("planar", "odometryRate"), ("planar", "cmdTimeout")])
def test_drive_tags(tmp_path, drives, drive, tag, text):
    urdf = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{text}</{tag}>", drives[drive])
    command = (lambda plugin: plugin.set_command(0.5, 0.0, 0.5)) if drive == "planar" else (
        lambda plugin: plugin.set_command(0.5, 0.5))
    moved = run(tmp_path, urdf, command)
    assert moved is None or moved < 1e-3


SONARS = (SONAR_SENSOR.format(name="front", plugin=RANGE_PLUGIN.format(radiation="ultrasound", noise=0))
          + SONAR_SENSOR.format(name="rear", plugin=HECTOR_SONAR_PLUGIN.format(noise=0)))
SENSOR_ROBOTS = {"hector": HECTOR_ROBOT.format(heading=0, imu="", gps=""), "sonar": SONAR_ROBOT.format(sensors=SONARS),
                 "bumper": BUMPER_ROBOT.format(collision=BUMPER_LUMPED_COLLISION)}
HECTOR_FILES = ("libhector_gazebo_ros_imu.so", "libhector_gazebo_ros_gps.so", "libhector_gazebo_ros_magnetic.so")
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
    urdf = SENSOR_ROBOTS[robot]
    if f"<{tag}>" in urdf:
        urdf = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{value}</{tag}>", urdf)
    else:
        for filename in HECTOR_FILES:
            urdf = urdf.replace(f'filename="{filename}">', f'filename="{filename}"><{tag}>{value}</{tag}>')
    moved = run(tmp_path, urdf)
    assert moved is None or moved < 1e-3


@pytest.fixture(scope="module")
def tricycle():
    return expand_xacro(TRICYCLE_XACRO, odometry_source="encoder")


@pytest.mark.parametrize("value", BAD_VALUES)
@pytest.mark.parametrize("axis", [0, 1])
def test_tricycle_commands(tmp_path, tricycle, axis, value):
    command = [0.3, 0.2]
    command[axis] = value
    assert run(tmp_path, tricycle, lambda plugin: plugin.set_command(*command)) < 1e-3


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", ["actuatedWheelDiameter", "encoderWheelDiameter", "encoderWheelSeparation",
                                 "wheelTorque", "updateRate", "wheelAcceleration", "wheelSpeedTolerance",
                                 "steeringSpeed", "steeringAngleTolerance", "gaussianNoise", "samples", "min", "max"])
def test_tricycle_and_block_laser_tags(tmp_path, tricycle, tag, text):
    urdf = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{text}</{tag}>", tricycle)
    moved = run(tmp_path, urdf, lambda plugin: plugin.set_command(0.3, 0.2))
    assert moved is None or moved < 1e-3


@pytest.fixture(scope="module")
def stereo_head():
    return expand_xacro(STEREO_XACRO, rate="50")


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", ["horizontal_fov", "width", "near", "far", "hackBaseline", "updateRate",
                                 "gaussianNoise", "pose"])
def test_stereo_head_tags(tmp_path, stereo_head, tag, text):
    """The multicamera's, the ft sensor's (gaussianNoise, updateRate) and the f3d's inputs."""
    value = " ".join([text] * 6) if tag == "pose" else text
    urdf = re.sub(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{value}</{tag}>", stereo_head)
    moved = run(tmp_path, urdf)
    assert moved is None or moved < 1e-3


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("tag", ["multiplier", "offset", "sensitiveness", "maxEffort"])
def test_mimic_tags(tmp_path, tag, text):
    plugin = MIMIC_PLUGIN_BLOCK.format(extra=f"<hasPID/><{tag}>{text}</{tag}>" if tag == "maxEffort"
                                       else f"<{tag}>{text}</{tag}>")
    urdf = MIMIC_GRIPPER.format(mimic="", plugin=plugin.replace("<multiplier>-1</multiplier>", "")
                          .replace("<offset>0.002</offset>", "") if tag in ("multiplier", "offset") else plugin)
    moved = run(tmp_path, urdf)
    assert moved is None or moved < 1e-3


@pytest.mark.parametrize("text", TAG_TEXTS)
@pytest.mark.parametrize("attribute", ["multiplier", "offset"])
def test_urdf_mimic_attributes(tmp_path, attribute, text):
    mimic = f'<mimic joint="left_finger_joint" {attribute}="{text}"/>'
    moved = run(tmp_path, MIMIC_GRIPPER.format(mimic=mimic, plugin=""))
    assert moved is None or moved < 1e-3
