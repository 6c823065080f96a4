"""The key bindings are the course's."""

from mbot_teleop.keymap import HELP, MOVE_BINDINGS, QUIT_KEY, SPEED_BINDINGS, STOP_KEYS


def test_move_keys_form_the_course_grid():
    # Rows u i o / j k l / m , . with k in the middle as a stop key.
    assert MOVE_BINDINGS == {
        'u': (1, 1), 'i': (1, 0), 'o': (1, -1),
        'j': (0, 1), 'l': (0, -1),
        'm': (-1, -1), ',': (-1, 0), '.': (-1, 1),
    }
    assert 'k' in STOP_KEYS


def test_speed_keys_scale_by_ten_percent():
    assert SPEED_BINDINGS == {
        'q': (1.1, 1.1), 'z': (0.9, 0.9),
        'w': (1.1, 1.0), 'x': (0.9, 1.0),
        'e': (1.0, 1.1), 'c': (1.0, 0.9),
    }


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
