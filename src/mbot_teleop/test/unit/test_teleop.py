"""The teleop cycle: ramp limits, stop keys, speed keys and the idle stop."""

import pytest

from mbot_teleop.teleop import IDLE_LIMIT, KeyAction, Teleop, idle_limit_for, ramp


def run(teleop, keys):
    """Feed one key per cycle ('' = a poll with no key); return the (linear, angular) commands."""
    commands = []
    for key in keys:
        teleop.cycle(key)
        commands.append((teleop.linear, teleop.angular))
    return commands


def linear(commands):
    return [pytest.approx(v) for v, _ in commands]


@pytest.mark.parametrize('current, target, expected', [
    (0.0, 0.2, 0.02), (0.19, 0.2, 0.2), (0.2, 0.2, 0.2),
    (0.2, 0.0, 0.18), (-0.19, -0.2, -0.2), (0.01, -0.2, -0.01),
])
def test_ramp_moves_at_most_one_step(current, target, expected):
    assert ramp(current, target, 0.02) == pytest.approx(expected)


# The course's ramp steps (0.02 m/s and 0.1 rad/s a cycle) are checked by what the keys do, not by the constants.
def test_forward_ramps_to_speed_in_linear_steps():
    commands = run(Teleop(0.2, 1.0), 'i' * 12)
    assert [v for v, _ in commands] == pytest.approx([0.02 * n for n in range(1, 11)] + [0.2, 0.2])
    assert all(w == 0.0 for _, w in commands)


def test_turn_ramps_to_turn_in_angular_steps():
    commands = run(Teleop(0.2, 1.0), 'j' * 11)
    assert [w for _, w in commands] == pytest.approx([0.1 * n for n in range(1, 11)] + [1.0])
    assert all(v == 0.0 for v, _ in commands)


@pytest.mark.parametrize('key, direction', [
    ('u', (1, 1)), ('i', (1, 0)), ('o', (1, -1)), ('j', (0, 1)),
    ('l', (0, -1)), ('m', (-1, -1)), (',', (-1, 0)), ('.', (-1, 1)),
])
def test_each_move_key_reaches_its_direction(key, direction):
    teleop = Teleop(0.2, 1.0)
    run(teleop, key * 10)
    x, th = direction
    assert (teleop.linear, teleop.angular) == pytest.approx((0.2 * x, 1.0 * th))


def test_reversing_ramps_through_zero():
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'i' * 10)
    assert linear(run(teleop, ',' * 3)) == [0.18, 0.16, 0.14]


@pytest.mark.parametrize('stop_key', [' ', 'k'])
def test_stop_keys_stop_at_once(stop_key):
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'u' * 10)
    assert teleop.cycle(stop_key) is KeyAction.STOP
    assert (teleop.linear, teleop.angular) == (0.0, 0.0)
    # The direction is gone too: idle cycles keep it stopped.
    assert run(teleop, ['']) == [(0.0, 0.0)]


def test_idle_stop_after_five_idle_cycles_then_ramps_down():
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'i' * 10)
    commands = run(teleop, [''] * 6)
    # Four idle cycles keep the target; the fifth drops it, and the ramp takes it down.
    assert linear(commands) == [0.2, 0.2, 0.2, 0.2, 0.18, 0.16]


def test_unbound_keys_count_as_idle():
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'i' * 10)
    assert teleop.cycle('a') is KeyAction.IDLE
    assert linear(run(teleop, 'fgh\x1b')) == [0.2, 0.2, 0.2, 0.18]


def test_move_and_speed_keys_restart_the_idle_count():
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'i' * 10)
    commands = run(teleop, ['', '', '', '', 'i', '', '', '', '', 'w', '', '', '', ''])
    assert min(v for v, _ in commands) == pytest.approx(0.2)


def test_idle_limit_none_holds_the_direction():
    teleop = Teleop(0.2, 1.0, idle_limit=None)
    run(teleop, 'i' * 10)
    assert linear(run(teleop, [''] * 50))[-1] == 0.2


@pytest.mark.parametrize('key, speed, turn', [
    ('q', 0.22, 1.1), ('z', 0.18, 0.9),
    ('w', 0.22, 1.0), ('x', 0.18, 1.0),
    ('e', 0.2, 1.1), ('c', 0.2, 0.9),
])
def test_speed_keys_scale_the_speeds(key, speed, turn):
    teleop = Teleop(0.2, 1.0)
    assert teleop.cycle(key) is KeyAction.SPEED
    assert (teleop.speed, teleop.turn) == pytest.approx((speed, turn))


def test_speed_key_retargets_a_moving_robot():
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'i' * 10)
    assert linear(run(teleop, 'w' + 'i' * 2)) == [0.22, 0.22, 0.22]
    assert linear(run(teleop, ['z', ''])) == [0.2, 0.198]


def test_quit_key_leaves_the_command_alone():
    teleop = Teleop(0.2, 1.0)
    run(teleop, 'i' * 3)
    assert teleop.cycle('\x03') is KeyAction.QUIT
    assert teleop.linear == pytest.approx(0.06)


@pytest.mark.parametrize('key_timeout, limit', [
    (0.5, IDLE_LIMIT), (0.1, 1), (0.01, 1), (1.0, 10), (0.0, None)])
def test_idle_limit_for_key_timeout(key_timeout, limit):
    assert idle_limit_for(key_timeout) == limit
