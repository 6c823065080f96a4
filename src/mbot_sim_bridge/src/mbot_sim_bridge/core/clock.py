"""Update timers on sim time, the way Gazebo's plugins pace themselves.

A timer never counts calls: it compares sim time with its last firing and advances that by whole periods
(``last += period``), so a rate holds exactly over a long run instead of drifting with the step size.
"""
import math
import sys

# Sim time is a whole number of steps times the step size; this absorbs the rounding of that product.
_EPSILON = 1e-9


class UpdateTimer:
    """Fires at ``rate`` Hz of sim time; rate ≤ 0 fires on every step.

    ``strict`` copies the diff drive's ``now - last > period`` (it fires one step after each period
    boundary); otherwise the sensors' ``now - last >= period`` applies.
    """

    def __init__(self, rate: float, strict: bool = False, start: float = 0.0):
        self.period = 1.0 / rate if rate > 0 else 0.0
        self.strict = strict
        self.last = start

    def reset(self, now: float):
        self.last = now

    def due(self, now: float) -> bool:
        if self.period == 0.0:
            return True
        elapsed = now - self.last
        if (elapsed > self.period + _EPSILON) if self.strict else (elapsed >= self.period - _EPSILON):
            self.last += self.period
            if now - self.last > self.period:
                # Far behind (e.g. after a reset of the clock): restart from now rather than fire a burst.
                self.last = now
            return True
        return False

    def steps_until_due(self, now: float, step_size: float) -> int:
        """How many more physics steps until ``due`` can be true (at least 1)."""
        if self.period == 0.0:
            return 1
        remaining = self.last + self.period - now
        steps = remaining / step_size
        if not -sys.maxsize < steps < sys.maxsize:  # a period too long to count in steps: not due within a run
            return 1 if steps < 0 else sys.maxsize
        whole = math.floor(steps + _EPSILON) + 1 if self.strict else math.ceil(steps - _EPSILON)
        return max(1, whole)


def steps_until_past(deadline: float, now: float, step_size: float) -> int:
    """Physics steps until sim time first exceeds ``deadline`` (a rate publisher's ``last + period < now``),
    counted so that rounding can only make it one short: stopping a step early costs a stop, stepping past the
    deadline would delay the message."""
    remaining = (deadline - now) / step_size
    if not math.isfinite(remaining):  # a deadline of -inf (publish at once) or +inf (never); NaN: every step
        return sys.maxsize if remaining > 0 else 1
    return max(1, math.floor(remaining - 1e-6) + 1)


class EveryStopTimer:
    """Due whenever the loop stops for another event, never asking it to stop: the timer of a plugin whose
    work happens between the physics steps (``Plugin.on_step``, or ``Plugin.step_recorder`` with the recorded
    steps reported together)."""

    period = 0.0

    def reset(self, now: float):
        pass

    def due(self, now: float) -> bool:
        return True

    def steps_until_due(self, now: float, step_size: float) -> int:
        return sys.maxsize
