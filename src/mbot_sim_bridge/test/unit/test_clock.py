import math
import sys

import pytest

from mbot_sim_bridge.core.clock import UpdateTimer, steps_until_past

STEP = 0.001


def firing_steps(timer, steps):
    return [step for step in range(1, steps + 1) if timer.due(step * STEP)]


def test_strict_timer_fires_one_step_after_each_period_like_the_diff_drive():
    assert firing_steps(UpdateTimer(100.0, strict=True), 50) == [11, 21, 31, 41]


@pytest.mark.parametrize("rate", [5.5, 30.0, 100.0])
def test_rate_holds_over_a_long_run_without_drift(rate):
    fired = firing_steps(UpdateTimer(rate), 100000)
    assert len(fired) == int(100 * rate)


def test_zero_rate_fires_every_step():
    assert firing_steps(UpdateTimer(0.0), 5) == [1, 2, 3, 4, 5]


@pytest.mark.parametrize("strict", [False, True])
def test_steps_until_due_predicts_the_next_firing(strict):
    timer = UpdateTimer(5.5, strict=strict)
    now_step = 0
    for _ in range(20):
        ahead = timer.steps_until_due(now_step * STEP, STEP)
        for step in range(1, ahead):
            assert not timer.due((now_step + step) * STEP)
        now_step += ahead
        assert timer.due(now_step * STEP)


def test_reset_restarts_the_period():
    timer = UpdateTimer(10.0)
    assert timer.due(0.1)
    timer.reset(0.0)
    assert not timer.due(0.05) and timer.due(0.1)


def test_steps_until_past_never_steps_past_the_deadline():
    step = STEP
    assert steps_until_past(0.0055, 0.0, step) == 6  # the first step after 5.5 steps
    assert steps_until_past(0.005, 0.0, step) in (5, 6)  # at the boundary a step early is allowed, never later
    assert steps_until_past(-1.0, 0.0, step) == 1
    assert steps_until_past(-math.inf, 0.0, step) == steps_until_past(math.nan, 0.0, step) == 1
    assert steps_until_past(math.inf, 0.0, step) == sys.maxsize
