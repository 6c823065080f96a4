"""./mbot sim ends with the simulator's exit status when the simulator stops (server_required semantics)."""
import os
import signal
import subprocess

from mbot_sim_bridge.processes import free_port, stop_process_group

from ros_processes import TESTS, run, wait_until

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
