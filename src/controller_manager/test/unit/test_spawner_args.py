"""The spawner's command line is upstream's (ros_control 0.20)."""
import threading

from controller_manager.spawner import Spawner, parse_args


def test_defaults():
    args = parse_args(["joint_state_controller", "mobile_base_controller"])
    assert (args.stopped, args.wait_for, args.namespace, args.timeout, args.no_timeout, args.shutdown_timeout) == (
        False, None, None, 30, False, None)
    assert args.controllers == ["joint_state_controller", "mobile_base_controller"]


def test_options_and_service_names():
    args = parse_args(["--stopped", "--wait-for", "/ready", "--namespace", "/robot", "--timeout", "0",
                       "--shutdown-timeout", "2", "arm_controller"])
    assert args.stopped and args.wait_for == "/ready" and args.shutdown_timeout == "2"
    spawner = Spawner(args, threading.Event())
    assert spawner.timeout is None  # <= 0 waits for ever
    assert spawner.services["load_controller"] == "/robot/controller_manager/load_controller"
    relative = Spawner(parse_args(["--timeout", "5", "c"]), threading.Event())
    assert relative.services["switch_controller"] == "controller_manager/switch_controller"
    assert relative.timeout == 5
