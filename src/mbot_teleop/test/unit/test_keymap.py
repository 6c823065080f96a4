"""The key bindings are the course's: each key's meaning is checked by what it does (test_teleop.py's move, speed
and stop key tests); here, that no key has two meanings and the help shows them all."""

from mbot_teleop.keymap import HELP, MOVE_BINDINGS, QUIT_KEY, SPEED_BINDINGS, STOP_KEYS


def test_every_key_has_one_meaning():
    groups = [set(MOVE_BINDINGS), set(SPEED_BINDINGS), set(STOP_KEYS), {QUIT_KEY}]
    assert sum(len(group) for group in groups) == len(set().union(*groups))


def test_help_shows_every_bound_key():
    grid = HELP.split('Moving around:')[1].split('q/z')[0].split()
    assert sorted(grid) == sorted(set(MOVE_BINDINGS) | {'k'})
    for pair in ('q/z', 'w/x', 'e/c'):
        assert pair in HELP
    assert 'space key, k : force stop' in HELP
    assert 'CTRL-C to quit' in HELP
