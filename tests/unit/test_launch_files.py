"""Every launch file parses and resolves (roslaunch's own check), and the course's launch files are the
course's text: the includes, nodes, params and args that matter, compared with the course's published files."""
import glob
import os
import xml.etree.ElementTree as ET

import pytest
import roslaunch.loader
import roslaunch.rlutil

from ros_processes import TESTS

pytestmark = pytest.mark.long

WORKSPACE = os.path.dirname(TESTS)
LAUNCH_FILES = sorted(glob.glob(os.path.join(WORKSPACE, "src", "*", "launch", "*.launch"))
                      + glob.glob(os.path.join(TESTS, "*.test")))


def test_every_package_has_its_launch_files():
    names = {os.path.relpath(path, os.path.join(WORKSPACE, "src")) for path in LAUNCH_FILES}
    assert {"mbot_gazebo/launch/view_mbot_gazebo_empty_world.launch", "mbot_gazebo/launch/mbot_world.launch",
            "mbot_gazebo/launch/view_mbot_gazebo_play_ground.launch", "mbot_gazebo/launch/mbot_play_ground.launch",
            "mbot_gazebo/launch/view_mbot_gazebo_room.launch", "mbot_gazebo/launch/mbot_room.launch",
            "mbot_gazebo/launch/view_mbot_with_laser_gazebo.launch", "gazebo_ros/launch/empty_world.launch",
            "mbot_sim_bridge/launch/empty_world.launch", "mbot_description/launch/display_mbot_base_xacro.launch",
            "mbot_teleop/launch/mbot_teleop.launch"} <= names


@pytest.fixture(scope="module")
def commands_run_once():
    """A param's ``command`` (a xacro expansion, mostly) runs once per command line for the whole module: the
    launch files and the .test files that include them ran 164 commands, 37 of them different (11 of the 15 CPU
    seconds of the check). The same command line gives the same text; one that fails raises at its first run."""
    run_command = roslaunch.loader.Loader.param_value
    outputs = {}

    def param_value(self, verbose, name, ptype, value, textfile, binfile, command):
        if command is None:
            return run_command(self, verbose, name, ptype, value, textfile, binfile, command)
        if (ptype, command) not in outputs:
            outputs[ptype, command] = run_command(self, verbose, name, ptype, value, textfile, binfile, command)
        return outputs[ptype, command]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(roslaunch.loader.Loader, "param_value", param_value)
        yield


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=os.path.basename)
def test_launch_file_checks(path, commands_run_once):
    assert roslaunch.rlutil.check_roslaunch(path) is None


# The course's mbot_gazebo launch files (mbot_gazebo/launch/ as published with the course, the seed tutorial's
# view_mbot_gazebo_empty_world.launch), reduced to what changes behaviour. The model paths are the tutorial's
# layout, urdf/gazebo/ (the published copies keep the same files under urdf/xacro/gazebo/).
COURSE_ARGS = (("arg", "paused", "default", "false"), ("arg", "use_sim_time", "default", "true"),
               ("arg", "gui", "default", "true"), ("arg", "headless", "default", "false"),
               ("arg", "debug", "default", "false"))
COURSE_INCLUDE_ARGS = (("arg", "debug", "value", "$(arg debug)"), ("arg", "gui", "value", "$(arg gui)"),
                       ("arg", "paused", "value", "$(arg paused)"),
                       ("arg", "use_sim_time", "value", "$(arg use_sim_time)"),
                       ("arg", "headless", "value", "$(arg headless)"))
COURSE_NODES = (
    ("node", "joint_state_publisher", "joint_state_publisher", "joint_state_publisher", None, ()),
    ("node", "robot_state_publisher", "robot_state_publisher", "robot_state_publisher", None,
     (("param", "publish_frequency", "double", "50.0"),)),
    ("node", "urdf_spawner", "gazebo_ros", "spawn_model", "-urdf -model mbot -param robot_description", ()),
)


def course_text(world, model):
    world_arg = (("arg", "world_name", "value", "$(find mbot_gazebo)/worlds/" + world),) if world else ()
    world_pass = (("arg", "world_name", "value", "$(arg world_name)"),) if world else ()
    return (world_arg + COURSE_ARGS
            + (("include", "$(find gazebo_ros)/launch/empty_world.launch", world_pass + COURSE_INCLUDE_ARGS),
               ("param", "robot_description", None,
                f"$(find xacro)/xacro --inorder '$(find mbot_description)/urdf/gazebo/{model}'"))
            + COURSE_NODES)


COURSE_FILES = {
    "view_mbot_gazebo_empty_world.launch": course_text(None, "mbot_gazebo.xacro"),
    "view_mbot_gazebo_play_ground.launch": course_text("playground.world", "mbot_gazebo.xacro"),
    "view_mbot_gazebo_room.launch": course_text("room.world", "mbot_gazebo.xacro"),
    "view_mbot_with_laser_gazebo.launch": course_text("playground.world", "mbot_with_laser_gazebo.xacro"),
}


def _what_matters(element):
    """(tag, identifying attributes..., children) for arg, include, param and node elements, in file order."""
    def words(text):
        return " ".join(text.split()) if text is not None else None
    if element.tag == "arg":
        kind = "default" if "default" in element.attrib else "value"
        return ("arg", element.get("name"), kind, element.get(kind))
    if element.tag == "include":
        return ("include", element.get("file"), tuple(_what_matters(child) for child in element))
    if element.tag == "param":
        if element.get("command") is not None:
            return ("param", element.get("name"), None, words(element.get("command")))
        return ("param", element.get("name"), element.get("type"), element.get("value"))
    if element.tag == "node":
        return ("node", element.get("name"), element.get("pkg"), element.get("type"), words(element.get("args")),
                tuple(_what_matters(child) for child in element))
    raise AssertionError(f"unexpected <{element.tag}> in a course launch file")


@pytest.mark.parametrize("name", sorted(COURSE_FILES))
def test_course_launch_file_is_the_course_text(name):
    root = ET.parse(os.path.join(WORKSPACE, "src", "mbot_gazebo", "launch", name)).getroot()
    assert tuple(_what_matters(element) for element in root) == COURSE_FILES[name]
