"""Start-up behaviour seen from the command line: paused:=true holds /clock, unknown plugins warn once,
spawn_model waits for the simulator (or gives up after -timeout with one line)."""
import subprocess

import rosgraph
from mbot_sim_bridge.processes import stop_process_group
from ros_processes import call_service, rosrun, run, service_up, wait_until


def clock_message(ros_env, timeout):
    """One /clock message within ``timeout`` seconds, or None."""
    try:
        result = subprocess.run(["rostopic", "echo", "-n", "1", "/clock"], env=ros_env, capture_output=True,
                                text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    return result.stdout if result.returncode == 0 else None


def node_names(ros_env):
    """The nodes the master knows, as ``rosnode list`` prints them (asked from this process)."""
    state = rosgraph.Master("/test", master_uri=ros_env["ROS_MASTER_URI"]).getSystemState()
    return {node for kind in state for _, nodes in kind for node in nodes}


GADGET = "<robot name='gadget'><link name='body'/></robot>"
TELEPORTING_GADGET = ("<robot name='gadget'><link name='body'><inertial><mass value='1'/><inertia ixx='0.01' "
                      "iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial></link><gazebo>"
                      "<plugin name='beam' filename='libgazebo_ros_teleporter.so'/></gazebo></robot>")


def test_spawn_model_first_then_a_paused_simulator_and_an_unknown_plugin(ros_env, launch, tmp_path):
    """One start-up (a launch per behaviour cost two CPU seconds each), in an order launch files give it:
    spawn_model started before the simulator waits for it; the simulator started with paused:=true publishes no
    /clock until unpaused; the model, whose plugin is not emulated, spawns all the same with one warning, and
    the simulation carries on."""
    model = tmp_path / "gadget.urdf"
    model.write_text(TELEPORTING_GADGET)
    spawner = subprocess.Popen(rosrun("mbot_sim_bridge", "spawn_model", "-urdf", "-file", str(model),
                                      "-model", "gadget"), env=ros_env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        wait_until(lambda: spawner.poll() is not None or any(
            name.startswith("/spawn_model") for name in node_names(ros_env)), 30, "spawn_model's node")
        assert spawner.poll() is None, "spawn_model exited before the simulator was up: " + spawner.stdout.read()
        bridge = launch("mbot_sim_bridge", "empty_world.launch", "gui:=false", "paused:=true")
        output, _ = spawner.communicate(timeout=60)
    finally:
        stop_process_group(spawner)
    assert spawner.returncode == 0, output
    assert "spawned 'gadget'" in output
    wait_until(lambda: service_up(ros_env, "/gazebo/unpause_physics"), 60, "the simulator's services")
    wait_until(lambda: "libgazebo_ros_teleporter.so" in bridge.log_path.read_text(), 30, "the warning")
    # A window in which a running simulator would publish hundreds of /clock messages.
    assert clock_message(ros_env, timeout=3) is None, "/clock was published while paused"
    call_service(ros_env, "/gazebo/unpause_physics")
    assert clock_message(ros_env, timeout=30) is not None, "the simulation carries on"
    warnings = [line for line in bridge.log_path.read_text().splitlines() if "libgazebo_ros_teleporter.so" in line]
    assert len(warnings) == 1 and "[WARN]" in warnings[0] and "is not emulated" in warnings[0], warnings


def test_spawn_model_timeout_without_a_simulator_is_one_line(ros_env, tmp_path):
    model = tmp_path / "gadget.urdf"
    model.write_text(GADGET)
    result = run(rosrun("mbot_sim_bridge", "spawn_model", "-urdf", "-file", str(model), "-model", "gadget",
                        "-timeout", "0.5"), ros_env)
    assert result.returncode == 1
    assert "Traceback" not in result.stderr, result.stderr
    assert "spawn_model: service /gazebo/spawn_urdf_model did not appear within 0.5 s (-timeout)" in result.stderr
