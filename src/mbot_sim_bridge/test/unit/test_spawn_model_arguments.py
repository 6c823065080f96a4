"""spawn_model's -J: repeatable (joint, position) pairs as numbers; a position that is not a number is refused
with one line by the argument parser, before anything is spawned."""
import pytest

from mbot_sim_bridge.spawn_model import parse_arguments

BASE = ["-urdf", "-file", "arm.urdf", "-model", "arm"]


def test_every_J_pair_is_kept_in_order_with_its_position_as_a_number():
    arguments = parse_arguments(BASE + ["-J", "elbow_joint", "1.5", "-J", "wrist_1_joint", "-0.9"])
    assert arguments.J == [("elbow_joint", 1.5), ("wrist_1_joint", -0.9)]
    assert parse_arguments(BASE).J == []


def test_a_position_that_is_not_a_number_is_refused_in_one_line(capsys):
    with pytest.raises(SystemExit) as exit_code:
        parse_arguments(BASE + ["-J", "elbow_joint", "up"])
    assert exit_code.value.code == 2
    message = capsys.readouterr().err.splitlines()
    assert len(message) == 1 and "-J takes a joint name and a position" in message[0] and "'up'" in message[0]


def test_a_bad_command_line_is_one_line_without_the_usage(capsys):
    with pytest.raises(SystemExit) as exit_code:
        parse_arguments(BASE + ["-J", "elbow_joint"])
    assert exit_code.value.code == 2
    assert capsys.readouterr().err.splitlines() == [
        "spawn_model: argument -J: expected 2 arguments (spawn_model -h lists the options)"]
