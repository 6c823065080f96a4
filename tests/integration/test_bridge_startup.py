"""Start-up behaviour seen from the command line: paused:=true holds /clock, unknown plugins warn once."""
import subprocess

from ros_processes import run, wait_until


def clock_message(ros_env, timeout):
    """One /clock message within ``timeout`` seconds, or None."""
    try:
        result = subprocess.run(["rostopic", "echo", "-n", "1", "/clock"], env=ros_env, capture_output=True,
                                text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    return result.stdout if result.returncode == 0 else None


def service_up(ros_env, name):
    return name in run(["rosservice", "list"], ros_env).stdout.split()


def test_started_paused_no_clock_until_unpaused(ros_env, launch):
    launch("mbot_sim_bridge", "empty_world.launch", "gui:=false", "paused:=true")
    wait_until(lambda: service_up(ros_env, "/gazebo/unpause_physics"), 60, "the simulator's services")
    # A window in which a running simulator would publish hundreds of /clock messages.
    assert clock_message(ros_env, timeout=3) is None, "/clock was published while paused"
    assert run(["rosservice", "call", "/gazebo/unpause_physics"], ros_env).returncode == 0
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
