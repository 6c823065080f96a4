"""The selection of twist_mux without ROS: upstream's rules at their edges, and the parameters' errors."""
import math

from twist_mux.mux import TwistMux, huge_field, non_finite_field, parse_handles

TOPICS = [{"name": "input1", "topic": "vel_1", "timeout": 0.7, "priority": 5},
          {"name": "input2", "topic": "vel_2", "timeout": 0.0, "priority": 1},
          {"name": "input3", "topic": "vel_3", "timeout": 0.3, "priority": 10}]
LOCKS = [{"name": "emergency_255", "topic": "lock_1", "timeout": 0.5, "priority": 255},
         {"name": "emergency_10", "topic": "lock_2", "timeout": 0.0, "priority": 10}]


def mux():
    inputs, errors = parse_handles("velocity", TOPICS, "~topics")
    locks, lock_errors = parse_handles("lock", LOCKS, "~locks")
    assert errors == lock_errors == []
    return TwistMux(inputs, locks), {handle.name: handle for handle in inputs + locks}


def test_highest_live_priority_passes_and_the_lower_resumes_after_its_timeout():
    selection, handles = mux()
    selection.on_lock(handles["emergency_255"], False, 10.0)
    assert selection.on_twist(handles["input1"], 10.0)
    assert selection.on_twist(handles["input3"], 10.1)
    assert not selection.on_twist(handles["input1"], 10.2)
    assert selection.on_twist(handles["input1"], 10.41)  # input3 heard at 10.1, timeout 0.3: expired


def test_a_lock_masks_priorities_strictly_below_its_own():
    selection, handles = mux()
    selection.on_lock(handles["emergency_255"], False, 10.0)
    selection.on_lock(handles["emergency_10"], True, 10.0)
    assert not selection.on_twist(handles["input1"], 10.0)
    assert selection.on_twist(handles["input3"], 10.0)


def test_a_heartbeat_lock_engages_when_it_times_out_and_the_passing_input_gets_one_stop():
    selection, handles = mux()
    selection.on_lock(handles["emergency_255"], False, 10.0)
    assert selection.on_twist(handles["input1"], 10.0)
    assert not selection.stop_due(10.4)
    assert selection.lock_priority(10.51) == 255
    assert selection.stop_due(10.51)
    assert not selection.stop_due(10.6)  # once
    assert not selection.on_twist(handles["input1"], 10.6)


def test_no_stop_for_an_input_that_had_already_timed_out():
    selection, handles = mux()
    selection.on_lock(handles["emergency_255"], False, 10.0)
    assert selection.on_twist(handles["input3"], 10.0)
    selection.on_lock(handles["emergency_255"], False, 10.4)
    selection.on_lock(handles["emergency_10"], False, 10.4)
    assert not selection.stop_due(10.4)  # input3 expired at 10.3


def test_upstream_edges_priority_zero_never_passes_and_time_starts_at_zero():
    inputs, _ = parse_handles("velocity", [{"name": "zero", "topic": "z", "timeout": 0, "priority": 0}], "~topics")
    assert not TwistMux(inputs, []).on_twist(inputs[0], 1.0)
    # A heartbeat lock never heard counts as heard at time 0 (upstream's initial stamp): free until its timeout.
    selection, handles = mux()
    assert selection.lock_priority(0.4) == 0
    assert selection.lock_priority(0.6) == 255


def test_ties_go_to_the_first_in_the_list():
    inputs, _ = parse_handles("velocity", [{"name": "a", "topic": "a", "timeout": 0, "priority": 7},
                                           {"name": "b", "topic": "b", "timeout": 0, "priority": 7}], "~topics")
    selection = TwistMux(inputs, [])
    assert selection.on_twist(inputs[0], 1.0)
    assert not selection.on_twist(inputs[1], 1.0)


def test_bad_entries_are_named_and_left_out_the_rest_kept():
    entries = [{"name": "ok", "topic": "t", "timeout": 0.5, "priority": 300},
               {"name": "nan", "topic": "t", "timeout": math.nan, "priority": 1},
               {"name": "neg", "topic": "t", "timeout": -1, "priority": 1},
               {"name": "frac", "topic": "t", "timeout": 1, "priority": 1.5},
               {"name": "missing", "topic": "t"},
               "not a dict",
               {"name": "", "topic": "t", "timeout": 1, "priority": 1},
               {"name": "inf", "topic": "t", "timeout": math.inf, "priority": -1e300}]
    handles, errors = parse_handles("velocity", entries, "/twist_mux/topics")
    assert [(handle.name, handle.priority) for handle in handles] == [("ok", 255), ("inf", 0)]
    assert len(errors) == 6
    assert errors[0].startswith("parameter /twist_mux/topics[1]: timeout must be")
    assert "missing timeout, priority" in errors[3]
    assert parse_handles("lock", {"a": 1}, "~locks")[1][0].startswith("parameter ~locks: expected a list")
    assert parse_handles("lock", None, "~locks") == ([], [])


def test_non_finite_field_names_the_first():
    assert non_finite_field((0, 0, 0, 0, 0, 0)) is None
    assert non_finite_field((1e308, math.nan, math.inf, 0, 0, 0))[0] == "linear.y"
    assert non_finite_field((0, 0, 0, 0, 0, -math.inf)) == ("angular.z", -math.inf)


def test_status_is_upstreams_text():
    selection, handles = mux()
    selection.on_lock(handles["emergency_255"], False, 1.0)
    values = dict(selection.status(1.0))
    assert values["velocity input1"] == " masked (listening to vel_1 @ 0.700000s with priority #5)"
    assert values["velocity input2"] == " unmasked (listening to vel_2 @ 0.000000s with priority #1)"
    assert values["lock emergency_10"] == " free (listening to lock_2 @ 0.000000s with priority #10)"
    assert values["current priority"] == "0"


def test_huge_field_names_the_first_beyond_the_limit():
    assert huge_field((1.0, -2.0, 0, 0, 0, 3.0)) is None
    assert huge_field((1.0, 1e308, 0, 0, 0, -1e5)) == ("linear.y", 1e308)
