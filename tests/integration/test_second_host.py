"""rviz on a workstation, as the README describes it: the simulation in one network namespace, a ROS client in
another, joined by a veth pair; ROS_MASTER_URI and ROS_IP set as the README says. /scan, /tf and /clock must
reach the client. Needs root and iproute2's `ip netns`; without them the test says so and skips.
"""
import os
import shutil
import subprocess
import sys
import textwrap

import pytest
from mbot_sim_bridge.processes import stop_process_group

from ros_processes import TESTS

ROOT = os.path.dirname(TESTS)
# A subnet of the veth pair only, inside namespaces this test makes; the pid keeps parallel runs apart.
SUBNET = f"10.200.{os.getpid() % 250 + 1}"
SIM_ADDRESS, WORKSTATION_ADDRESS = SUBNET + ".1", SUBNET + ".2"
ARRIVAL_TIMEOUT = 180

CLIENT = textwrap.dedent("""
    import sys
    import time

    import rospy
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import LaserScan
    from tf2_msgs.msg import TFMessage

    arrived = set()
    rospy.init_node("workstation_client", disable_signals=True)
    for topic, kind in (("/scan", LaserScan), ("/tf", TFMessage), ("/clock", Clock)):
        rospy.Subscriber(topic, kind, lambda message, topic=topic: arrived.add(topic))
    end = time.monotonic() + float(sys.argv[1])
    while time.monotonic() < end and len(arrived) < 3:
        time.sleep(0.1)
    print("arrived: " + " ".join(sorted(arrived)), flush=True)
    rospy.signal_shutdown("done")
    sys.exit(0 if len(arrived) == 3 else 1)
""")


def _ip(*arguments):
    return subprocess.run(["ip", *arguments], capture_output=True, text=True)


@pytest.fixture
def namespaces():
    """Two network namespaces joined by a veth pair; both deleted afterwards, whatever happened."""
    if os.geteuid() != 0:
        pytest.skip(f"network namespaces need root; this test runs as uid {os.geteuid()}")
    if shutil.which("ip") is None:
        pytest.skip("no 'ip' command (iproute2) to make network namespaces")
    tag = os.getpid()
    sim, workstation = f"mbot_sim_{tag}", f"mbot_ws_{tag}"
    created = []
    try:
        for name in (sim, workstation):
            result = _ip("netns", "add", name)
            if result.returncode != 0:
                pytest.skip(f"cannot make a network namespace: {result.stderr.strip()}")
            created.append(name)
        veth_sim, veth_workstation = f"mbs{tag}", f"mbw{tag}"
        steps = [("link", "add", veth_sim, "netns", sim, "type", "veth", "peer", "name", veth_workstation,
                  "netns", workstation)]
        ends = ((sim, veth_sim, SIM_ADDRESS), (workstation, veth_workstation, WORKSTATION_ADDRESS))
        for name, device, address in ends:
            steps += [("-n", name, "link", "set", "lo", "up"),
                      ("-n", name, "addr", "add", address + "/24", "dev", device),
                      ("-n", name, "link", "set", device, "up")]
        for step in steps:
            result = _ip(*step)
            assert result.returncode == 0, f"ip {' '.join(step)}: {result.stderr}"
        yield sim, workstation
    finally:
        for name in created:
            _ip("netns", "delete", name)


def test_a_workstation_receives_scan_tf_and_clock(namespaces, tmp_path):
    sim, workstation = namespaces
    master = f"http://{SIM_ADDRESS}:11311"
    environment = dict(os.environ, ROS_MASTER_URI=master, ROS_LOG_DIR=str(tmp_path), PYTHONUNBUFFERED="1")
    log_path = tmp_path / "sim.log"
    with open(log_path, "w") as log:
        # On the simulation host: export ROS_IP=...; ./mbot sim laser (it starts the master itself).
        simulation = subprocess.Popen(["ip", "netns", "exec", sim, os.path.join(ROOT, "mbot"), "sim", "laser"],
                                      env=dict(environment, ROS_IP=SIM_ADDRESS), stdout=log,
                                      stderr=subprocess.STDOUT, start_new_session=True)
    try:
        # On the workstation: export ROS_MASTER_URI=http://<simulation host>:11311 ROS_IP=<workstation>.
        client = subprocess.run(["ip", "netns", "exec", workstation, sys.executable, "-c", CLIENT,
                                 str(ARRIVAL_TIMEOUT)], env=dict(environment, ROS_IP=WORKSTATION_ADDRESS),
                                capture_output=True, text=True, timeout=ARRIVAL_TIMEOUT + 60)
        simulation_log = log_path.read_text()[-3000:]
        assert client.returncode == 0, f"{client.stdout}{client.stderr}\nsimulation:\n{simulation_log}"
        assert "arrived: /clock /scan /tf" in client.stdout
    finally:
        stop_process_group(simulation)
