"""xacro as Noetic runs it (xacro_noetic over PyPI's xacro 2.x): a YAML-driven arm macro written the Noetic way
(xacro.load_yaml, dotted access, !degrees, $(find) arguments) expands through the Python API and through
`rosrun xacro xacro --inorder`; a macro called without the xacro: prefix expands with a deprecation warning, as
the course's descriptions need; an unknown package is named."""
import math
import os
import subprocess
import xml.etree.ElementTree as ET

import pytest
import xacro_noetic as xacro

HERE = os.path.dirname(os.path.abspath(__file__))
ARM = os.path.join(HERE, "..", "descriptions", "yaml_arm.urdf.xacro")
COURSE_MBOT = os.path.join(HERE, "..", "..", "..", "mbot_description", "urdf", "gazebo", "mbot_gazebo.xacro")


def joints(urdf: str) -> dict:
    return {joint.get("name"): joint for joint in ET.fromstring(urdf).findall("joint")}


def test_a_yaml_driven_macro_expands_with_limits_in_radians():
    arm = joints(xacro.process_file(ARM).toxml())
    pan, elbow = arm["shoulder_pan_joint"].find("limit"), arm["elbow_joint"].find("limit")
    assert float(pan.get("upper")) == pytest.approx(2 * math.pi)  # !degrees 360
    assert float(pan.get("velocity")) == pytest.approx(math.pi)  # !degrees 180
    assert float(elbow.get("lower")) == pytest.approx(-math.pi)
    assert float(elbow.get("effort")) == 28.0
    assert arm["shoulder_pan_joint"].find("origin").get("xyz") == "0 0 0.1625"


def test_rosrun_xacro_inorder_gives_the_same_and_warns_about_the_unprefixed_call():
    result = subprocess.run(["rosrun", "xacro", "xacro", "--inorder", ARM], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    assert joints(result.stdout).keys() == {"shoulder_pan_joint", "elbow_joint"}
    assert "deprecated: xacro tags should be prepended with 'xacro' xml namespace: <plain_link>" in result.stderr


def test_the_course_mbot_expands_its_unprefixed_macro_calls():
    links = {link.get("name") for link in ET.fromstring(xacro.process_file(COURSE_MBOT).toxml()).findall("link")}
    assert {"base_link", "left_wheel_link", "right_wheel_link"} <= links


def test_an_unknown_package_is_named(tmp_path):
    path = tmp_path / "missing.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://wiki.ros.org/xacro">'
                    '<xacro:include filename="$(find no_such_package)/urdf/x.xacro"/></robot>')
    result = subprocess.run(["rosrun", "xacro", "xacro", str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode != 0
    assert "package 'no_such_package' not found on ROS_PACKAGE_PATH" in result.stderr
