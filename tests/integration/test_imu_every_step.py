"""libgazebo_ros_imu.so at updateRate 0 through the bridge: a message per physics step in lockstep, recorded
every step and sent in batches (core/sensors/imu.py), repeated byte for byte after reset_simulation."""
import os

from mbot_sim_bridge.processes import stop_process_group
from ros_processes import TESTS, run

SCRIPT = os.path.join(TESTS, "nodes", "imu_every_step_script.py")
LAUNCH = os.path.join(TESTS, "launch", "lockstep_imu.launch")


def test_every_step_imu_in_lockstep(ros_env, launch):
    bridge = launch(LAUNCH)
    result = run(["python3", SCRIPT], ros_env, timeout=120)
    stop_process_group(bridge)
    print(result.stdout)
    assert result.returncode == 0, result.stdout + result.stderr + bridge.log_path.read_text()[-3000:]
    assert result.stdout.count("figure:") == 2
