"""The selection of twist_mux without ROS: upstream's rules at their edges, and the parameters' errors; then a
seeded fuzz of configurations with clashing names and topics and cmd_vel_out remapped onto them
(MBOT_FULL_SWEEP=1 draws more)."""
import math
import os

from hypothesis import given, settings
from hypothesis import strategies as st

from twist_mux.mux import TwistMux, check_topics, huge_field, non_finite_field, parse_handles

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
    assert len(errors) == 8  # six entries left out, two priorities clamped
    assert errors[1].startswith("parameter /twist_mux/topics[1]: timeout must be")
    assert "missing timeout, priority" in errors[4]
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


def test_an_out_of_range_priority_is_clamped_as_upstream_and_said():
    """Upstream reads the priority as an int and clamps it into [0, 255] silently; here the clamp is said."""
    handles, errors = parse_handles("velocity", [{"name": "low", "topic": "t", "timeout": 0, "priority": -5},
                                                 {"name": "high", "topic": "u", "timeout": 0, "priority": 300}],
                                    "/twist_mux/topics")
    assert [handle.priority for handle in handles] == [0, 255]
    assert errors == ["parameter /twist_mux/topics[0] ('low'): priority -5 is outside [0, 255]; 0 is used, as "
                      "upstream clamps it (an input of priority 0 never passes)",
                      "parameter /twist_mux/topics[1] ('high'): priority 300 is outside [0, 255]; 255 is used, as "
                      "upstream clamps it"]


def test_a_duplicate_input_name_is_left_out_with_one_line_naming_both():
    """Upstream selects by name, so two inputs of one name pass together whatever their priorities."""
    handles, errors = parse_handles("velocity", [{"name": "joy", "topic": "a", "timeout": 0, "priority": 10},
                                                 {"name": "nav", "topic": "b", "timeout": 0, "priority": 5},
                                                 {"name": "joy", "topic": "c", "timeout": 0, "priority": 1}],
                                    "~topics")
    assert [handle.topic for handle in handles] == ["a", "b"]
    assert errors == ["parameter ~topics[2]: name 'joy' is already that of ~topics[0]; entry left out"]
    # Locks act each on its own whatever their names: two of one name are kept, as upstream.
    locks, lock_errors = parse_handles("lock", [{"name": "stop", "topic": "a", "timeout": 0, "priority": 10},
                                                {"name": "stop", "topic": "b", "timeout": 0, "priority": 5}], "~locks")
    assert len(locks) == 2 and lock_errors == []


def resolve(name):
    """rospy.resolve_name in the node's namespace /base with the remappings a launch file may give."""
    mapped = {"/base/cmd_vel_out": "/base/joy_vel"}
    full = name if name.startswith("/") else "/base/" + name
    return mapped.get(full, full)


def test_an_input_on_the_output_topic_is_left_out_it_would_feed_itself():
    inputs, _ = parse_handles("velocity", [{"name": "joy", "topic": "joy_vel", "timeout": 0.5, "priority": 10},
                                           {"name": "nav", "topic": "/base/nav_vel", "timeout": 0.5, "priority": 5}],
                              "/base/twist_mux/topics")
    kept, locks, errors = check_topics(inputs, [], resolve("cmd_vel_out"), resolve)
    assert [handle.name for handle in kept] == ["nav"] and locks == []
    assert errors == ["parameter /base/twist_mux/topics[0] ('joy'): topic /base/joy_vel is cmd_vel_out, this "
                      "node's output: the input would feed itself; entry left out"]


def test_a_lock_on_an_inputs_topic_leaves_the_input_out_with_one_line_naming_both():
    """A topic carries one type: a Bool lock and a Twist input cannot share it (rospy hands one subscriber the
    other's messages; upstream's roscpp throws at the second subscription, uncaught, and the node ends). The
    input goes: a configuration mistake never drops a lock."""
    inputs, _ = parse_handles("velocity", [{"name": "joy", "topic": "joy_vel", "timeout": 0.5, "priority": 10},
                                           {"name": "nav", "topic": "nav_vel", "timeout": 0.5, "priority": 5}],
                              "~topics")
    locks, _ = parse_handles("lock", [{"name": "pause", "topic": "/base/nav_vel", "timeout": 0, "priority": 100}],
                             "~locks")
    kept, kept_locks, errors = check_topics(inputs, locks, resolve("cmd_vel"), resolve)
    assert [handle.name for handle in kept] == ["joy"] and kept_locks == locks
    assert errors == ["parameter ~topics[1] ('nav'): topic /base/nav_vel is also that of the lock parameter "
                      "~locks[0] ('pause'), which listens for std_msgs/Bool; the input is left out, the lock kept"]


FULL_SWEEP = bool(os.environ.get("MBOT_FULL_SWEEP"))
TOPIC_NAMES = ("joy_vel", "/base/joy_vel", "nav_vel", "cmd_vel", "cmd_vel_out", "/cmd_vel_out", "~private")
ENTRY = st.fixed_dictionaries({"name": st.sampled_from(["joy", "nav", "pause", "stop"]),
                               "topic": st.sampled_from(TOPIC_NAMES),
                               "timeout": st.sampled_from([0, 0.5, 1e9]),
                               "priority": st.one_of(st.integers(-300, 600), st.sampled_from([-1e300, 1e300, 255.0]))})


@settings(derandomize=True, deadline=None, database=None, max_examples=3000 if FULL_SWEEP else 150)
@given(topics=st.lists(ENTRY, max_size=6), locks=st.lists(ENTRY, max_size=3),
       output=st.sampled_from(["cmd_vel_out", "joy_vel", "/base/nav_vel", "/elsewhere"]))
def test_fuzz_clashing_names_and_topics_are_refused_one_line_each(topics, locks, output):
    """Every entry is kept or named in one line; no kept input shares a name, feeds the output or sits on a
    lock's topic; every lock is kept; a message on a kept input passes only when it is the one selected."""
    def in_namespace(name):
        return ("/base/twist_mux/" + name[1:] if name.startswith("~") else
                name if name.startswith("/") else "/base/" + name)

    def resolve(name):  # as rospy.resolve_name in the node /base/twist_mux with cmd_vel_out:=output
        full = in_namespace(name)
        return in_namespace(output) if full == "/base/cmd_vel_out" else full
    inputs, input_errors = parse_handles("velocity", topics, "~topics")
    lock_handles, _ = parse_handles("lock", locks, "~locks")
    kept, kept_locks, topic_errors = check_topics(inputs, lock_handles, resolve("cmd_vel_out"), resolve)
    assert kept_locks == lock_handles and len(lock_handles) == len(locks)
    left_out = [line.split("]")[0] for line in input_errors + topic_errors if line.endswith(
        ("entry left out", "the lock kept"))]
    assert len(set(left_out)) == len(left_out) == len(topics) - len(kept)
    assert len({handle.name for handle in kept}) == len(kept)
    lock_topics = {resolve(lock.topic) for lock in lock_handles}
    for handle in kept:
        assert 0 <= handle.priority <= 255
        assert resolve(handle.topic) != resolve("cmd_vel_out") and resolve(handle.topic) not in lock_topics
    selection = TwistMux(kept, kept_locks)
    for step, handle in enumerate(kept * 2):
        now = 1.0 + 0.1 * step
        best = selection.selected(now)
        assert selection.on_twist(handle, now) == (selection.selected(now) is handle)
        assert best is None or best.priority > 0
