"""Start-up behaviour seen from the command line: paused:=true holds /clock, unknown plugins warn once,
spawn_model waits for the simulator (or gives up after -timeout with one line)."""
import subprocess

from mbot_sim_bridge.processes import stop_process_group
from ros_processes import call_service, run, service_up, wait_until


def clock_message(ros_env, timeout):
    """One /clock message within ``timeout`` seconds, or None."""
    try:
        result = subprocess.run(["rostopic", "echo", "-n", "1", "/clock"], env=ros_env, capture_output=True,
                                text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    return result.stdout if result.returncode == 0 else None


def test_started_paused_no_clock_until_unpaused(ros_env, launch):
    launch("mbot_sim_bridge", "empty_world.launch", "gui:=false", "paused:=true")
    wait_until(lambda: service_up(ros_env, "/gazebo/unpause_physics"), 60, "the simulator's services")
    # A window in which a running simulator would publish hundreds of /clock messages.
    assert clock_message(ros_env, timeout=3) is None, "/clock was published while paused"
    call_service(ros_env, "/gazebo/unpause_physics")
    assert clock_message(ros_env, timeout=30) is not None


def test_unknown_plugin_warns_once_and_the_model_still_spawns(ros_env, launch, tmp_path):
    bridge = launch("mbot_sim_bridge", "empty_world.launch", "gui:=false")
    model = tmp_path / "gadget.urdf"
    model.write_text("<robot name='gadget'><link name='body'><inertial><mass value='1'/><inertia ixx='0.01' "
                     "iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial></link><gazebo>"
                     "<plugin name='beam' filename='libgazebo_ros_teleporter.so'/></gazebo></robot>")
    spawned = run(["rosrun", "mbot_sim_bridge", "spawn_model", "-urdf", "-file", str(model), "-model", "gadget"],
                  ros_env)
    assert spawned.returncode == 0, spawned.stderr
    wait_until(lambda: "libgazebo_ros_teleporter.so" in bridge.log_path.read_text(), 30, "the warning")
    assert clock_message(ros_env, timeout=30) is not None, "the simulation carries on"
    warnings = [line for line in bridge.log_path.read_text().splitlines() if "libgazebo_ros_teleporter.so" in line]
    assert len(warnings) == 1 and "[WARN]" in warnings[0] and "is not emulated" in warnings[0], warnings


GADGET = "<robot name='gadget'><link name='body'/></robot>"


def test_spawn_model_started_first_waits_for_the_simulator(ros_env, launch, tmp_path):
    model = tmp_path / "gadget.urdf"
    model.write_text(GADGET)
    spawner = subprocess.Popen(["rosrun", "mbot_sim_bridge", "spawn_model", "-urdf", "-file", str(model),
                                "-model", "gadget"], env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, start_new_session=True)
    try:
        wait_until(lambda: spawner.poll() is not None or any(
            name.startswith("/spawn_model") for name in run(["rosnode", "list"], ros_env).stdout.split()),
            30, "spawn_model's node")
        assert spawner.poll() is None, "spawn_model exited before the simulator was up: " + spawner.stdout.read()
        launch("mbot_sim_bridge", "empty_world.launch", "gui:=false")
        output, _ = spawner.communicate(timeout=60)
    finally:
        stop_process_group(spawner)
    assert spawner.returncode == 0, output
    assert "spawned 'gadget'" in output


def test_spawn_model_timeout_without_a_simulator_is_one_line(ros_env, tmp_path):
    model = tmp_path / "gadget.urdf"
    model.write_text(GADGET)
    result = run(["rosrun", "mbot_sim_bridge", "spawn_model", "-urdf", "-file", str(model), "-model", "gadget",
                  "-timeout", "0.5"], ros_env)
    assert result.returncode == 1
    assert "Traceback" not in result.stderr, result.stderr
    assert "spawn_model: service /gazebo/spawn_urdf_model did not appear within 0.5 s (-timeout)" in result.stderr
