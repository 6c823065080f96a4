"""Lockstep stepping and bit-identical reruns: a command published before a step request is applied before the
first step, two launches of the same script give byte-identical /odom, /scan, /joint_states and /tf from the
bridge, and reset_simulation followed by the same script gives them again within one run; the wait behind the
first guarantee also covers bytes a subscriber's reader thread has taken out of its socket but not parsed yet.

robot_state_publisher's /tf is recorded too, and shown, but not compared: it subscribes joint_states with a
queue of one, so of the two joint_states messages the bridge sends per cycle (the diff drive's wheels, the
other joints) it drops one or not depending on thread scheduling, and it drops joint states older than its
own ROS time allows, which depends on when /clock reaches it."""
import contextlib
import os
import pickle
import struct
import subprocess
import threading
import time

import pytest
import rosgraph
from mbot_sim_bridge.processes import PrivateMaster, stop_process_group
from ros_processes import TESTS, call_service, run, service_up, wait_until

SCRIPT = os.path.join(TESTS, "nodes", "lockstep_script.py")
LOG_STAMP = os.path.join(TESTS, "nodes", "log_stamp.py")
LAUNCH = os.path.join(TESTS, "launch", "lockstep_mbot.launch")
# Messages that start with a std_msgs/Header: rospy writes its per-publisher counter into header.seq.
TOPICS_WITH_HEADER = ("/odom", "/scan", "/joint_states")
STEP = "/gazebo/step_simulation"
STOP_SECONDS = 5.0  # roslaunch's own Ctrl-C handling included


def start_bridge(ros_env, directory):
    log_path = directory / "roslaunch.log"
    with open(log_path, "w") as log:
        bridge = subprocess.Popen(["roslaunch", LAUNCH], env=ros_env, stdout=log, stderr=subprocess.STDOUT,
                                  start_new_session=True)
    bridge.log_path = log_path
    return bridge


def recorded_run(ros_env, bridge, directory):
    output = directory / "recording.pickle"
    result = run(["python3", SCRIPT, str(output)], ros_env, timeout=240)
    assert result.returncode == 0, result.stdout + result.stderr + bridge.log_path.read_text()[-3000:]
    with open(output, "rb") as stream:
        recording = pickle.load(stream)
    # The bridge's warnings (a step that could not wait for its subscribers, say) explain a difference.
    recording["warnings"] = [line for line in bridge.log_path.read_text().splitlines() if "WARN" in line]
    return recording


@contextlib.contextmanager
def recorded_launch(directory):
    """(environment, bridge, recording): the launch, on a master of its own, after the script ran against it."""
    with PrivateMaster() as master:
        ros_env = dict(master.environment, ROS_LOG_DIR=str(directory), PYTHONUNBUFFERED="1")
        bridge = start_bridge(ros_env, directory)
        try:
            yield ros_env, bridge, recorded_run(ros_env, bridge, directory)
        finally:
            stop_process_group(bridge)


@pytest.fixture(scope="module")
def launches(tmp_path_factory):
    """The script's recordings from two launches, and the second launch's (environment, bridge), left running for
    test_step_simulation_answers_every_count: a third launch for that test alone cost three CPU seconds."""
    with recorded_launch(tmp_path_factory.mktemp("first")) as (_, _, first):
        pass
    with recorded_launch(tmp_path_factory.mktemp("second")) as (ros_env, bridge, second):
        yield (first, second), (ros_env, bridge)


def bridge_only(recording, zero_seq=False):
    """The bridge's own messages; ``zero_seq`` zeroes header.seq, rospy's per-publisher counter, which runs on
    across a reset."""
    return {key: [struct.pack("<I", 0) + raw[4:] if zero_seq and key[0] in TOPICS_WITH_HEADER else raw
                  for raw in messages]
            for key, messages in recording.items() if key[1] == "/gazebo"}


def summary(recording):
    return ", ".join(f"{topic} from {node}: {len(messages)}"
                     for (topic, node), messages in sorted(recording.items()))


def test_lockstep_orders_commands_and_reruns_are_bit_identical(launches):
    (first, second), _ = launches
    assert first["moved"] == [True] * 20, "a command published before step_simulation was not applied first"
    recording = first["first"]
    for key in [("/odom", "/gazebo"), ("/scan", "/gazebo"), ("/joint_states", "/gazebo"), ("/tf", "/gazebo")]:
        assert len(recording.get(key, [])) > 10, f"too few {key} messages: {summary(recording)}"
    # robot_state_publisher turns the bridge's joint_states into /tf at its own pace: its subscriber keeps one
    # message, so on a loaded machine it drops most of a fast-stepped run. It must take part, at any rate.
    assert recording.get(("/tf", "/robot_state_publisher")), f"no /tf from robot_state_publisher: {summary(recording)}"
    print(f"figure: lockstep script recorded {summary(recording)}")
    assert bridge_only(first["after_reset"], True) == bridge_only(recording, True), \
        "reset_simulation did not repeat the run; the bridge warned: " + "\n".join(first["warnings"])
    assert bridge_only(second["first"]) == bridge_only(recording), (
        "a second launch of the same script differs; the bridge warned: " + "\n".join(second["warnings"]))
    assert bridge_only(second["after_reset"]) == bridge_only(first["after_reset"])
    identical = sum(len(messages) for messages in bridge_only(recording).values())
    print(f"figure: two launches and a reset: {identical} serialized messages of the bridge identical byte for byte")


def test_step_simulation_answers_every_count(launches):
    _, (ros_env, bridge) = launches
    wait_until(lambda: service_up(ros_env, STEP), 90, "the simulator's step_simulation")
    # The launch ran the script: reset_simulation brings it back to its start, sim time 0.
    call_service(ros_env, "/gazebo/reset_simulation")
    response = call_service(ros_env, STEP, "{steps: 0}")
    assert response["success"] and response["sim_time"] == 0.0, response
    largest = 2 ** 32 - 1  # uint32: a negative count or 2**63 cannot even be sent (the client refuses to encode it)
    response = call_service(ros_env, STEP, f"{{steps: {largest}}}")
    assert not response["success"] and "step in parts" in response["status_message"], response
    assert "\n" not in response["status_message"]
    with pytest.raises(Exception, match="(?i)uint32|out of range|format requires|argument out of range"):
        call_service(ros_env, STEP, f"{{steps: {2 ** 63}}}")
    response = call_service(ros_env, STEP, "{steps: 10}")
    assert response["success"] and response["sim_time"] == pytest.approx(0.01), response
    # The simulator's own ROS time is sim time too (it sets rospy's time as it publishes /clock, rather than
    # subscribing to its own /clock): what it logs now is stamped 0.01.
    log_stamp = subprocess.Popen(["python3", LOG_STAMP, "no_such_model"], env=ros_env, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
    try:
        assert log_stamp.stdout.readline().strip() == "ready", log_stamp.stderr.read()
        response = call_service(ros_env, "/gazebo/delete_model", "{model_name: no_such_model}")
        assert not response["success"], response
        assert log_stamp.stdout.readline().strip() == "0.010000000", log_stamp.stderr.read()
    finally:
        log_stamp.kill()
        log_stamp.communicate()
    subscribers = dict(rosgraph.Master("/test", master_uri=ros_env["ROS_MASTER_URI"]).getSystemState()[1])
    assert "/gazebo" not in subscribers["/clock"], subscribers["/clock"]
    # The longest call allowed (an hour of sim time) still ends at Ctrl-C within a second or two.
    long_call = threading.Thread(target=call_ignoring_errors, args=(ros_env, STEP, "{steps: 3600000}"), daemon=True)
    long_call.start()
    assert run(["rostopic", "echo", "-n", "1", "/clock"], ros_env, timeout=60).returncode == 0
    started = time.monotonic()
    assert stop_process_group(bridge)
    assert time.monotonic() - started < STOP_SECONDS
    long_call.join(timeout=30)


def call_ignoring_errors(*arguments):
    try:
        call_service(*arguments)
    except Exception:  # the simulator stops under the call: its answer never comes, which is the point
        pass


def test_drain_waits_for_bytes_a_reader_has_taken_but_not_parsed(ros_env):
    result = run(["python3", os.path.join(TESTS, "nodes", "drain_script.py")], ros_env, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.split() == ["handled"] * 5, result.stdout + result.stderr
