"""Message stamps against the node's clock, without ROS: data stamped too far ahead is refused with one warning per
input and the filter keeps predicting (and so publishing); data a little ahead waits in the queue while the
filter predicts on; ``history_length`` warnings say what was given and what is used. Then a seeded fuzz of
stamps from far in the past to far in the future (MBOT_FULL_SWEEP=1 draws more)."""
import os

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robot_localization.ekf import STATE_SIZE, VX, VYAW
from robot_localization.estimator import FUTURE_LIMIT, Estimator, PoseInput, Source, TwistInput
from robot_localization.geometry import Transform
from robot_localization.params import read_config

FREQUENCY = 30.0
FULL_SWEEP = bool(os.environ.get("MBOT_FULL_SWEEP"))
FUZZ = settings(derandomize=True, deadline=None, database=None, print_blob=True,
                max_examples=2000 if FULL_SWEEP else 60, suppress_health_check=[HealthCheck.too_slow])


def members(*indices):
    update = np.zeros(STATE_SIZE, dtype=bool)
    update[list(indices)] = True
    return update


def estimator():
    warnings = {}
    result = Estimator(lambda *args: Transform(), warnings.setdefault, topics={"twist0": "/wheel/twist"})
    result.warnings = warnings
    # Below the update period, so that every update without data due predicts (1/frequency, the default, sits on
    # the period and rounding decides).
    result.filter.sensor_timeout = 0.5 / FREQUENCY
    return result


TWIST = Source("twist0", members(VX, VYAW))


def twist(stamp, speed=1.0):
    return TwistInput(stamp, "base_link", np.array([speed, 0.0, 0.0]), np.array([0.0, 0.0, 0.1]), np.eye(6) * 1e-3)


def updates(filter_estimator, start, seconds):
    """The periodic update from ``start`` for ``seconds``: the estimate's time after each."""
    times = start + np.arange(1, int(seconds * FREQUENCY) + 1) / FREQUENCY
    stamps = []
    for now in times:
        filter_estimator.integrate(now)
        stamps.append(filter_estimator.filter.last_measurement_time)
    return times, np.array(stamps)


def test_data_stamped_far_ahead_is_refused_once_and_the_filter_keeps_predicting():
    """The probe's case: 2 s of data stamped 100 s ahead. Upstream queues it, and with data in the queue does not
    predict, so it publishes nothing until the clock reaches the stamps; here it is refused, said once."""
    subject = estimator()
    subject.twist(twist(10.0), TWIST, now=10.0)
    subject.integrate(10.0)
    now = 10.0
    for _ in range(int(2 * FREQUENCY)):
        now += 1.0 / FREQUENCY
        subject.twist(twist(now + 100.0), TWIST, now=now)
        subject.integrate(now)
    assert subject.filter.last_measurement_time == now
    assert not subject.queue
    [(key, line)] = subject.warnings.items()
    assert key == "twist0_future"
    assert "twist0 (/wheel/twist)" in line and "100.000 s ahead" in line and f"{FUTURE_LIMIT:g} s" in line
    # Data on time from the same input is taken again at once: the refused stamps did not become its last time.
    subject.twist(twist(now + 0.01, speed=2.0), TWIST, now=now + 0.01)
    subject.integrate(now + 0.02)
    assert subject.filter.state[VX] > 1.5


def test_data_a_little_ahead_waits_in_the_queue_while_the_filter_predicts():
    """Within FUTURE_LIMIT a stamp is the sender's clock running a little ahead: the data waits (as upstream) and
    is fused when its time comes, while the periodic update predicts on as it does without data."""
    subject = estimator()
    subject.twist(twist(10.0), TWIST, now=10.0)
    subject.integrate(10.0)
    ahead = 10.0 + 0.8 * FUTURE_LIMIT
    subject.twist(twist(ahead, speed=2.0), TWIST, now=10.0)
    times, stamps = updates(subject, 10.0, 0.5 * FUTURE_LIMIT)
    assert np.allclose(stamps, times)
    assert len(subject.queue) == 1 and not subject.warnings
    updates(subject, times[-1], FUTURE_LIMIT)
    assert not subject.queue and subject.filter.state[VX] > 1.5


def test_the_clock_is_optional_for_replays():
    subject = estimator()
    subject.twist(twist(1000.0), TWIST)
    assert len(subject.queue) == 1 and not subject.warnings


def test_a_refused_odometry_message_is_said_once_for_the_input():
    subject = estimator()
    pose_source, twist_source = Source("odom0_pose", members(0, 1)), Source("odom0_twist", members(VX))
    for offset in (50.0, 60.0):
        pose = PoseInput(offset, "odom", np.zeros(3), np.array([0, 0, 0, 1.0]), np.eye(6))
        subject.odometry(pose, twist(offset), pose_source, twist_source, now=0.5)
    assert list(subject.warnings) == ["odom0_future"] and not subject.queue


def history_lines(parameters):
    _, problems = read_config({"print_diagnostics": False, **parameters})
    return [line for _, line in problems if line.startswith("~history_length")]


def test_history_length_warnings_say_what_was_given_and_what_is_used():
    [unused] = history_lines({"history_length": -1})
    assert unused.startswith("~history_length: -1.0 specified, but smooth_lagged_data is false")
    [negative] = history_lines({"history_length": -1, "smooth_lagged_data": True})
    assert "-1.0 specified" in negative and "1.0 s is used" in negative
    assert history_lines({"history_length": 2.0, "smooth_lagged_data": True}) == []


# Offsets of a stamp from the clock: on time, jitter, the sender's clock a little ahead or behind, far off.
OFFSETS = st.one_of(st.sampled_from([0.0, -1e-3, 1e-3, FUTURE_LIMIT, -FUTURE_LIMIT, 100.0, -100.0, 1e6, -1e6]),
                    st.floats(-2 * FUTURE_LIMIT, 2 * FUTURE_LIMIT), st.floats(-1e3, 1e3))
EVENTS = st.lists(st.tuples(st.sampled_from(["twist0", "twist1"]), OFFSETS, st.integers(0, 3)), min_size=1,
                  max_size=120 if FULL_SWEEP else 40)


@FUZZ
@given(events=EVENTS, smoothing=st.booleans())
def test_fuzz_stamps_never_silence_the_filter(events, smoothing):
    """Each event is a message with its stamp offset from the clock, then some periodic updates. After every
    update with nothing newly due the estimate is within sensor_timeout of the clock (the node publishes), it
    stays finite, and the queue holds nothing beyond FUTURE_LIMIT."""
    subject = estimator()
    subject.history_length = 1.0 if smoothing else None
    sources = {name: Source(name, members(VX, VYAW)) for name in ("twist0", "twist1")}
    now = 100.0
    subject.twist(twist(now), sources["twist0"], now=now)
    for name, offset, steps in events:
        subject.twist(twist(now + offset), sources[name], now=now)
        for _ in range(steps):
            now += 1.0 / FREQUENCY
            subject.integrate(now)
        subject.integrate(now)
        subject.integrate(now)
        assert 0.0 <= now - subject.filter.last_measurement_time < subject.filter.sensor_timeout
        assert np.isfinite(subject.filter.state).all() and np.isfinite(subject.filter.covariance).all()
        assert all(stamp <= now + FUTURE_LIMIT for stamp, _, _ in subject.queue)
    assert set(subject.warnings) <= {"twist0_future", "twist1_future", "twist0_timestamp", "twist1_timestamp",
                                     "history_length"}
