"""Bad input gets one clear line naming what is wrong, and no traceback."""
import subprocess

import pytest
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group

from ros_processes import call_service, rosrun, run

pytestmark = pytest.mark.long

BAD_DRIVE = """<robot name="lopsided">
  <link name="chassis"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.3 0.2 0.05"/></geometry></collision></link>
  <gazebo><plugin name="drive" filename="libgazebo_ros_diff_drive.so">
    <leftJoint>left_wheel_joint</leftJoint><rightJoint>right_wheel_joint</rightJoint></plugin></gazebo>
</robot>"""


def one_error_line(output, *expected):
    assert "Traceback" not in output, output
    lines = [line for line in output.splitlines() if all(text in line for text in expected)]
    assert lines, f"no line containing {expected} in:\n{output}"


def spawn(ros_env, *arguments):
    return run(rosrun("mbot_sim_bridge", "spawn_model", "-urdf", "-model", "probe", *arguments), ros_env)


@pytest.fixture(scope="module")
def simulator(tmp_path_factory):
    """(environment, bridge): one simulator on a master of its own for the module's spawns, which leave it as
    they found it (a launch per test cost two CPU seconds each)."""
    directory = tmp_path_factory.mktemp("simulator")
    with PrivateMaster() as master:
        environment = dict(master.environment, ROS_LOG_DIR=str(directory), PYTHONUNBUFFERED="1")
        with open(directory / "roslaunch.log", "w") as log:
            bridge = subprocess.Popen(["roslaunch", "mbot_sim_bridge", "empty_world.launch", "gui:=false"],
                                      env=environment, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            yield environment, bridge
        finally:
            stop_process_group(bridge)


@pytest.fixture
def sim_env(simulator):
    return simulator[0]


def test_spawn_without_robot_description(sim_env):
    result = spawn(sim_env, "-param", "robot_description")
    assert result.returncode == 1
    one_error_line(result.stderr, "spawn_model:", "parameter /robot_description is not set")


def test_spawn_from_a_file_that_is_not_xml(sim_env, tmp_path):
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'>")
    result = spawn(sim_env, "-file", str(broken))
    assert result.returncode == 1
    one_error_line(result.stderr, "spawn_model:", str(broken), "is not valid XML")


def test_spawn_from_a_missing_file(sim_env):
    result = spawn(sim_env, "-file", "/nonexistent/robot.urdf")
    assert result.returncode == 1
    one_error_line(result.stderr, "cannot read model file /nonexistent/robot.urdf")


@pytest.mark.parametrize("xml, expected", [
    ("<sdf version='1.6'><model name='m'/></sdf>", "its root element is <sdf>, not <robot>"),
    ("<robot name='x'><link name='a'/><joint name='j' type='fixed'><parent link='a'/><child link='b'/></joint>"
     "</robot>", "joint 'j': child link 'b' is not defined"),
    (BAD_DRIVE, "<leftJoint> names joint 'left_wheel_joint', which the robot does not have"),
])
def test_spawn_refused_by_the_simulator_names_the_problem(simulator, tmp_path, xml, expected):
    environment, bridge = simulator
    model = tmp_path / "model.urdf"
    model.write_text(xml)
    result = spawn(environment, "-file", str(model))
    assert result.returncode == 1, result.stderr
    one_error_line(result.stderr, "spawn_model: spawning 'probe' failed:", expected)
    # The simulator carries on: a good model spawns afterwards (and is deleted: the next test spawns 'probe' too).
    good = tmp_path / "good.urdf"
    good.write_text("<robot name='ok'><link name='a'/></robot>")
    assert spawn(environment, "-file", str(good)).returncode == 0
    assert call_service(environment, "/gazebo/delete_model", "{model_name: probe}")["success"]
    assert bridge.poll() is None


def test_bridge_with_a_missing_world_exits_with_one_line(ros_env):
    result = run(["roslaunch", "mbot_sim_bridge", "empty_world.launch", "gui:=false",
                  "world_name:=/nonexistent/nowhere.world", "server_required:=true"], ros_env)
    one_error_line(result.stdout + result.stderr, "[FATAL]", "/nonexistent/nowhere.world")


def test_bridge_with_malformed_world_names_file_and_line(ros_env, tmp_path):
    world = tmp_path / "broken.world"
    world.write_text("<?xml version='1.0'?>\n<sdf version='1.6'>\n<world name='w'>\n</sdf>\n")
    result = run(["roslaunch", "mbot_sim_bridge", "empty_world.launch", "gui:=false",
                  f"world_name:={world}", "server_required:=true"], ros_env)
    one_error_line(result.stdout + result.stderr, "[FATAL]", "broken.world:4")
