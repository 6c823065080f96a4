"""The course's teleop cycle, free of ROS and of the terminal.

One cycle is one key poll: a key, or nothing after CYCLE_PERIOD. Each cycle
updates the target from the key and then ramps the command toward it; the
caller publishes ``(linear, angular)`` after every cycle.
"""

import enum

from mbot_teleop.keymap import MOVE_BINDINGS, QUIT_KEY, SPEED_BINDINGS, STOP_KEYS

# Longest cycle: the key poll's timeout, in seconds.
CYCLE_PERIOD = 0.1
# The course's ramp: the command moves toward the target by at most this per cycle.
LINEAR_STEP = 0.02  # m/s
ANGULAR_STEP = 0.1  # rad/s
# The course drops the target to zero on the fifth idle cycle in a row ("count > 4").
IDLE_LIMIT = 5


class KeyAction(enum.Enum):
    """What a cycle's key did."""

    MOVE = 'move'
    SPEED = 'speed'
    STOP = 'stop'
    QUIT = 'quit'
    IDLE = 'idle'  # no key, or a key without a binding


def ramp(current, target, max_step):
    """Return current moved toward target by at most max_step."""
    return min(max(target, current - max_step), current + max_step)


def idle_limit_for(key_timeout):
    """Return the idle cycles that make up key_timeout seconds; None (never) for 0."""
    if key_timeout == 0:
        return None
    return max(1, round(key_timeout / CYCLE_PERIOD))


class Teleop:
    """Keyboard teleop state, advanced one cycle at a time.

    ``speed`` (m/s) and ``turn`` (rad/s) are the scales that the speed keys
    change. ``linear`` and ``angular`` are the ramped command. After
    ``idle_limit`` idle cycles in a row the target becomes zero; with None the
    last direction holds until a stop key.
    """

    def __init__(self, speed, turn, idle_limit=IDLE_LIMIT):
        self.speed = speed
        self.turn = turn
        self.idle_limit = idle_limit
        self.linear = 0.0
        self.angular = 0.0
        self._direction = (0, 0)
        self._idle_cycles = 0

    def cycle(self, key):
        """Run one cycle with the key read in it ('' if none); return what the key did."""
        action = self._apply(key)
        if action is not KeyAction.QUIT:
            x, th = self._direction
            self.linear = ramp(self.linear, self.speed * x, LINEAR_STEP)
            self.angular = ramp(self.angular, self.turn * th, ANGULAR_STEP)
        return action

    def _apply(self, key):
        if key in MOVE_BINDINGS:
            self._direction = MOVE_BINDINGS[key]
            self._idle_cycles = 0
            return KeyAction.MOVE
        if key in SPEED_BINDINGS:
            linear_factor, angular_factor = SPEED_BINDINGS[key]
            self.speed *= linear_factor
            self.turn *= angular_factor
            self._idle_cycles = 0
            return KeyAction.SPEED
        if key in STOP_KEYS:
            # Unlike the idle stop, this one skips the ramp.
            self._direction = (0, 0)
            self.linear = self.angular = 0.0
            return KeyAction.STOP
        if key == QUIT_KEY:
            return KeyAction.QUIT
        self._idle_cycles += 1
        if self.idle_limit is not None and self._idle_cycles >= self.idle_limit:
            self._direction = (0, 0)
        return KeyAction.IDLE
