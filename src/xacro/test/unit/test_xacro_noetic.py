"""xacro as Noetic runs it (xacro_noetic over PyPI's xacro 2.x): a YAML-driven arm macro written the Noetic way
(xacro.load_yaml, dotted access, !degrees, $(find) arguments) expands through the Python API and through
`rosrun xacro xacro --inorder`; a macro called without the xacro: prefix expands with a deprecation warning, as
the course's descriptions need, also through the bare `xacro` on the PATH, `import xacro` and a launch file's
`command="xacro ..."`; an unknown package is named."""
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
import xacro_noetic as xacro
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ARM = os.path.join(HERE, "..", "descriptions", "yaml_arm.urdf.xacro")
COURSE_MBOT = os.path.join(HERE, "..", "..", "..", "mbot_description", "urdf", "gazebo", "mbot_gazebo.xacro")
COURSE_MBOT_LINKS = ["base_footprint", "base_link", "back_caster_link", "left_wheel_link", "right_wheel_link"]


def joints(urdf: str) -> dict:
    return {joint.get("name"): joint for joint in ET.fromstring(urdf).findall("joint")}


def links(urdf: str) -> list:
    return [link.get("name") for link in ET.fromstring(urdf).findall("link")]


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
    assert links(xacro.process_file(COURSE_MBOT).toxml()) == COURSE_MBOT_LINKS


def test_the_bare_xacro_on_the_path_gives_what_rosrun_xacro_gives():
    bare = shutil.which("xacro")
    assert bare, "no xacro on the PATH"
    # PyPI's console script, as any pip install of xacro writes it again: the module it imports does the work.
    with open(bare) as script:
        assert "from xacro import main" in script.read()
    results = [subprocess.run(command + [COURSE_MBOT], capture_output=True, text=True, timeout=60)
               for command in ([bare], ["rosrun", "xacro", "xacro"])]
    assert [result.returncode for result in results] == [0, 0], results[0].stderr
    assert links(results[0].stdout) == COURSE_MBOT_LINKS
    assert results[0].stdout == results[1].stdout
    assert results[0].stderr == results[1].stderr
    assert "deprecated: xacro tags should be prepended with 'xacro' xml namespace: <wheel>" in results[0].stderr


def test_import_xacro_is_noetics_in_a_new_interpreter():
    program = "import sys, xacro; print(xacro.process_file(sys.argv[1]).toxml())"
    result = subprocess.run([sys.executable, "-c", program, COURSE_MBOT], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    assert links(result.stdout) == COURSE_MBOT_LINKS


def test_a_launch_file_calling_bare_xacro_loads_every_link(tmp_path):
    launch = tmp_path / "bare_xacro.launch"
    launch.write_text('<launch><arg name="model" default="$(find mbot_description)/urdf/gazebo/mbot_gazebo.xacro"/>'
                      '<param name="robot_description" command="xacro \'$(arg model)\'"/></launch>')
    # roslaunch evaluates the param's command as it does when launching; the process starts nothing.
    result = subprocess.run(["roslaunch", "--dump-params", str(launch)], capture_output=True, text=True,
                            timeout=60, env=dict(os.environ, ROS_LOG_DIR=str(tmp_path)))
    assert result.returncode == 0, result.stderr
    assert links(yaml.safe_load(result.stdout)["/robot_description"]) == COURSE_MBOT_LINKS


def test_an_unknown_package_is_named(tmp_path):
    path = tmp_path / "missing.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://wiki.ros.org/xacro">'
                    '<xacro:include filename="$(find no_such_package)/urdf/x.xacro"/></robot>')
    result = subprocess.run(["rosrun", "xacro", "xacro", str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode != 0
    assert "package 'no_such_package' not found on ROS_PACKAGE_PATH" in result.stderr
