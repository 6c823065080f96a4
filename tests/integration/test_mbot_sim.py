"""./mbot sim ends with the simulator's exit status when the simulator stops (server_required semantics)."""
import os
import re
import signal
import subprocess

from mbot_sim_bridge.processes import free_port, stop_process_group

from ros_processes import TESTS, run, wait_until
from xvfb import Xvfb

MBOT = os.path.join(os.path.dirname(TESTS), "mbot")


def _environment(tmp_path):
    # A master of its own on a free port: ./mbot sim starts one when none answers.
    return dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{free_port()}", ROS_LOG_DIR=str(tmp_path))


def test_sim_with_a_missing_world_returns_the_simulators_status(tmp_path):
    result = run([MBOT, "sim", "empty", "world_name:=/nonexistent/missing.world"], _environment(tmp_path),
                 timeout=120)
    output = result.stdout + result.stderr
    assert result.returncode == 1, output
    assert any("[FATAL]" in line and "/nonexistent/missing.world" in line for line in output.splitlines()), output
    assert "mbot sim: the simulator stopped (exit status 1)" in output


def test_sim_runs_until_interrupted(tmp_path):
    environment = _environment(tmp_path)
    log_path = tmp_path / "sim.log"
    with open(log_path, "w") as log:
        simulation = subprocess.Popen([MBOT, "sim", "empty"], env=environment, stdout=log, stderr=subprocess.STDOUT,
                                      start_new_session=True)
    try:
        wait_until(lambda: run(["rostopic", "echo", "-n", "1", "/odom"], environment, timeout=60).returncode == 0,
                   120, "/odom from ./mbot sim")
        assert simulation.poll() is None, log_path.read_text()
        os.killpg(simulation.pid, signal.SIGINT)
        assert simulation.wait(timeout=60) == 0, log_path.read_text()
    finally:
        stop_process_group(simulation)


def test_sim_refuses_an_argument_the_launch_file_does_not_declare(tmp_path):
    result = run([MBOT, "sim", "camera", "lockstep:=true"], _environment(tmp_path), timeout=120)
    assert result.returncode == 2, result.stdout + result.stderr
    assert ("mbot sim: view_mbot_with_camera_gazebo.launch has no argument 'lockstep'; it takes paused, "
            "use_sim_time, gui, headless, debug") in result.stderr


def test_sim_help_lists_each_worlds_arguments(tmp_path):
    result = run([MBOT, "sim", "--help", "empty"], _environment(tmp_path), timeout=120)
    assert result.returncode == 0, result.stderr
    assert "lockstep:=false    start paused; the simulation moves only through /gazebo/step_simulation" in result.stdout
    assert "world_name:=" in result.stdout and "x:=0    spawn x (m)" in result.stdout


def test_shell_puts_the_workspace_after_the_users_bashrc(tmp_path):
    # A ~/.bashrc that puts another python3 first (pyenv's and conda's do) must not hide the venv's.
    decoy = tmp_path / "decoy_bin"
    decoy.mkdir()
    (decoy / "python3").write_text("#!/bin/sh\necho decoy\n")
    (decoy / "python3").chmod(0o755)
    (tmp_path / ".bashrc").write_text(f'export PATH="{decoy}:$PATH"\n')
    result = subprocess.run([MBOT, "shell"], input='python3 -c "import rospy, xacro; print(\'workspace python\')"\n',
                            env=dict(_environment(tmp_path), HOME=str(tmp_path)), capture_output=True, text=True,
                            timeout=120)
    assert "workspace python" in result.stdout, result.stdout + result.stderr
    assert "decoy" not in result.stdout


def test_every_world_takes_what_mbot_sim_passes_it():
    """./mbot sim WORLD runs its launch file with gui:=true|false (and an rviz beside it with --rviz): every world
    the script names resolves to a launch file that declares gui, or ./mbot sim WORLD would refuse to start."""
    import roslaunch.arg_dump
    import roslaunch.rlutil
    with open(MBOT) as script:
        worlds = re.findall(r"^\s+([a-z_|]+)\) echo (\S+) (\S+\.launch) ;;$", script.read(), re.M)
    names = [name for names, _, _ in worlds for name in names.split("|")]
    assert {"empty", "room", "camera", "kinect", "multi", "rover", "holonomic", "tricycle", "stereo", "arm"} <= \
        set(names)
    for names, package, launch_file in worlds:
        path = roslaunch.rlutil.resolve_launch_arguments([package, launch_file])[0]
        assert "gui" in roslaunch.arg_dump.get_args([path]), f"{names}: {launch_file} takes no gui argument"


def test_teleop_and_rviz_say_to_start_the_simulator_first(tmp_path):
    environment = _environment(tmp_path)  # a port no master answers on
    for command in ("teleop", "rviz"):
        result = run([MBOT, command], environment, timeout=120)
        assert result.returncode == 1, result.stdout + result.stderr
        assert "no ROS master" in result.stderr and "start ./mbot sim WORLD first" in result.stderr, result.stderr


def test_every_rviz_config_the_wrappers_open_exists():
    """./mbot rviz CONFIG and ./mbot sim WORLD --rviz open $(rospack find mbot_description)/config/CONFIG.rviz
    (rover_description's for rover): each config the script names is there."""
    import rospkg
    with open(MBOT) as script:
        text = script.read()
    rviz_cases = text.split("rviz_config_for() {", 1)[1].split("esac", 1)[0]
    configs = set(re.findall(r"\) echo (\w+) ;;", rviz_cases)) | {"mbot_with_laser"}  # cmd_rviz's default
    packages = rospkg.RosPack()
    for config in configs:
        package = "rover_description" if config == "rover" else "mbot_description"
        assert os.path.isfile(os.path.join(packages.get_path(package), "config", config + ".rviz")), config


def test_the_crate_worlds_start_and_sim_rviz_opens_rviz(tmp_path):
    """The worlds no other test starts (mobile_test_robots' holonomic, tricycle and stereo), each through ./mbot sim
    on a master of its own, side by side, up to its robot's first message; the holonomic one with --rviz, whose
    rviz (on a private X display) subscribes /odom as mbot.rviz, the config ./mbot sim picks for it, says. Each
    is stopped once it has done its part, the stereo world (two cameras) first."""
    first_messages = {"stereo": "/stereo/left/camera_info", "tricycle": "/odom", "holonomic": "/odom"}
    with Xvfb(tmp_path / "xvfb.log") as server:
        environments, simulations = {}, {}
        try:
            for world in first_messages:
                (tmp_path / world).mkdir()  # its logs, and rviz's HOME (rviz writes ~/.rviz)
                environments[world] = dict(_environment(tmp_path / world), DISPLAY=server.display,
                                           LIBGL_ALWAYS_SOFTWARE="1", HOME=str(tmp_path / world))
                with open(tmp_path / world / "sim.log", "w") as log:
                    simulations[world] = subprocess.Popen(
                        [MBOT, "sim", world] + (["--rviz"] if world == "holonomic" else []),
                        env=environments[world], stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
            for world, topic in first_messages.items():
                wait_until(lambda: run(["rostopic", "echo", "-n", "1", "--noarr", topic], environments[world],
                                       timeout=120).returncode == 0,
                           180, f"{topic} from ./mbot sim {world} (log: {tmp_path / world / 'sim.log'})")
                if world == "holonomic":
                    wait_until(lambda: rviz_subscribes(environments["holonomic"], "/odom"), 120,
                               f"rviz to subscribe /odom (log: {tmp_path / 'holonomic' / 'sim.log'})")
                simulation = simulations[world]
                assert simulation.poll() is None, (tmp_path / world / "sim.log").read_text()
                os.killpg(simulation.pid, signal.SIGINT)
            for world, simulation in simulations.items():
                assert simulation.wait(timeout=60) == 0, (tmp_path / world / "sim.log").read_text()
        finally:
            for simulation in simulations.values():
                stop_process_group(simulation)


def rviz_subscribes(environment, topic):
    """Whether a node of rviz's (rosrun rviz rviz names itself /rviz_HOST_PID) subscribes ``topic``."""
    import rosgraph
    try:
        _, subscribers, _ = rosgraph.Master("/test", master_uri=environment["ROS_MASTER_URI"]).getSystemState()
    except (rosgraph.MasterError, OSError):
        return False
    return any(node.startswith("/rviz") for name, nodes in subscribers if name == topic for node in nodes)
