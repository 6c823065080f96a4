"""The batch spec: bad specs are refused with one line naming the key, runs expand with stable ids, and the core
(spec, results, report) imports no ROS."""
import math
import os
import subprocess
import sys
import textwrap

import pytest
from mbot_batch import spec
from mbot_batch.spec import SpecError

DECLARED = ("x", "y", "Y", "gui", "lockstep", "seed", "real_time_factor")


def resolver(reference, folder, where):
    """Launch files without roslaunch: 'pkg good.launch' exists and declares DECLARED, anything else is missing."""
    if reference == "pkg good.launch":
        return "/ws/pkg/good.launch", DECLARED
    if reference == "pkg noseed.launch":
        return "/ws/pkg/noseed.launch", ("gui", "lockstep")
    raise SpecError(f"{where}: no such launch file: {reference}")


@pytest.fixture
def write(tmp_path):
    (tmp_path / "scenario.py").write_text("")

    def write(text):
        path = tmp_path / "spec.yaml"
        path.write_text(textwrap.dedent(text))
        return str(path)
    return write


GOOD = """\
scenarios:
  drive:
    launch: pkg good.launch
    python: scenario.py
    metrics: {distance: {min: 1.0}}
matrix:
  seed: {range: 3}
  speed: [0.1, 0.2]
timeout: 30
retries: 2
"""


def load(path):
    return spec.load(path, resolver)


def test_a_good_spec_expands_to_every_combination_with_stable_ids(write):
    batch = load(write(GOOD))
    runs = batch.runs()
    assert len(runs) == 6
    assert len({run.run_id for run in runs}) == 6
    assert [run.run_id for run in load(write(GOOD)).runs()] == [run.run_id for run in runs]
    assert {(run.seed, run.scenario_params["speed"]) for run in runs} == {(s, v) for s in range(3) for v in (0.1, 0.2)}
    assert batch.retries == 2 and batch.timeout == 30.0


def test_the_run_id_depends_on_scenario_values_and_seed_only(write):
    reordered = GOOD.replace("  seed: {range: 3}\n  speed: [0.1, 0.2]", "  speed: [0.2, 0.1]\n  seed: [2, 1, 0]")
    retimed = GOOD.replace("timeout: 30", "timeout: 99")
    ids = {run.run_id for run in load(write(GOOD)).runs()}
    assert {run.run_id for run in load(write(reordered)).runs()} == ids
    assert {run.run_id for run in load(write(retimed)).runs()} == ids
    changed = GOOD.replace("speed: [0.1, 0.2]", "speed: [0.1, 0.3]")
    assert len({run.run_id for run in load(write(changed)).runs()} & ids) == 3


def test_matrix_targets_reach_launch_arguments_ros_parameters_and_the_scenario(write):
    text = GOOD.replace("  speed: [0.1, 0.2]", "  args.real_time_factor: [0]\n  params.mbot/gain: [1.5]\n"
                        "  start: [{args.x: 1.0, args.y: -2}]")
    run = load(write(text)).runs()[0]
    assert run.launch_args == {"gui": "false", "real_time_factor": "0", "x": "1.0", "y": "-2"}
    assert run.ros_params == {"/mbot/gain": 1.5}
    assert run.labels["start"] == "#0"


def test_random_poses_are_seeded_and_within_their_ranges(write):
    text = GOOD.replace("  speed: [0.1, 0.2]", "  start: {random_poses: {count: 4, seed: 7, x: [-1, 1], "
                        "y: [0, 0.5], Y: [-3, 3]}}")
    first, second = load(write(text)).matrix["start"], load(write(text)).matrix["start"]
    assert first == second and len(first) == 4 and len({pose["args.x"] for pose in first}) == 4
    assert all(-1 <= p["args.x"] <= 1 and 0 <= p["args.y"] <= 0.5 and -3 <= p["args.Y"] <= 3 for p in first)


@pytest.mark.parametrize("change, key", [
    (("retries: 2", "retries: 2\nworkers: 4"), "workers: unknown key"),
    (("    python: scenario.py", "    python: scenario.py\n    lunch: x"), "scenarios.drive.lunch: unknown key"),
    (("pkg good.launch", "pkg missing.launch"), "scenarios.drive.launch: no such launch file"),
    (("python: scenario.py", "python: nowhere.py"), "scenarios.drive.python: no such file"),
    (("  seed: {range: 3}\n  speed: [0.1, 0.2]", "  {}"), "matrix: empty"),
    (("speed: [0.1, 0.2]", "speed: []"), "matrix.speed: needs a non-empty list"),
    (("timeout: 30", "timeout: -5"), "timeout: must be a positive number of seconds"),
    (("timeout: 30", "timeout: .nan"), "timeout: nan is not a usable value"),
    (("speed: [0.1, 0.2]", "speed: [0.1, .nan]"), "matrix.speed[1]: nan is not a usable value"),
    (("speed: [0.1, 0.2]", "speed: [.inf]"), "matrix.speed[0]: inf is not a usable value"),
    (("speed: [0.1, 0.2]", "args.speed: [1]"), "matrix.args.speed: scenario 'drive''s launch file has no argument"),
    (("speed: [0.1, 0.2]", "args.seed: [1]"), "matrix.args.seed: 'seed' is set by the batch"),
    (("retries: 2", "retries: -1"), "retries: must be an integer >= 0"),
    (("retries: 2", "repetitions: 0"), "repetitions: must be an integer >= 1"),
    (("{distance: {min: 1.0}}", "{distance: {min: .nan}}"), "scenarios.drive.metrics.distance.min: nan"),
    (("{distance: {min: 1.0}}", "{distance: {at_least: 1}}"), "scenarios.drive.metrics.distance.at_least: unknown"),
    (("pkg good.launch", "pkg noseed.launch"), "scenarios.drive: noseed.launch declares no 'seed' argument"),
    (("    python: scenario.py", "    rostest: pkg good.launch"), "scenarios.drive.launch: a rostest scenario"),
    (("speed: [0.1, 0.2]", "speed: {random: 3}"), "matrix.speed: a mapping of values must be one generator"),
    # Specs that could not finish or could not pass.
    (("seed: {range: 3}", "seed: {range: 100000000}"), "matrix.seed.range: more than the 100000 runs"),
    (("seed: {range: 3}", "seed: {range: [0, 100000000000000000000000]}"), "matrix.seed.range: more than"),
    (("seed: {range: 3}", "seed: {range: [0, 10, 0]}"), "matrix.seed.range: a step of 0"),
    (("seed: {range: 3}", "seed: {range: 400}\n  other: {range: 400}"), "matrix: makes 320000 runs, more than"),
    (("retries: 2", "retries: 1000000000"), "retries: must be at most 10"),
    (("timeout: 30", "timeout: 1.0e+300"), "timeout: must be a positive number of seconds up to 86400"),
    (("seed: {range: 3}", "seed: [abc]"), "matrix.seed[0]: a seed must be an integer from 0 to 2147483647"),
    (("seed: {range: 3}", "seed: [1, 2.5]"), "matrix.seed[1]: a seed must be an integer"),
    (("seed: {range: 3}", "seed: [-1]"), "matrix.seed[0]: a seed must be an integer"),
    (("seed: {range: 3}", "seed: [4294967296]"), "matrix.seed[0]: a seed must be an integer"),
    (("speed: [0.1, 0.2]", "start: [{seed: x}]"), "matrix.start[0].seed: a seed must be an integer"),
    (("{distance: {min: 1.0}}", "{x: {min: 5, max: 1}}"), "scenarios.drive.metrics.x: min 5 is above max 1"),
    # Names that become folders, keys and ROS names.
    (("scenarios:\n  drive:", "name: ../../etc\nscenarios:\n  drive:"), "name: '../../etc' is not a plain name"),
    (("scenarios:\n  drive:", "scenarios:\n  a/b:"), "scenarios.a/b: 'a/b' is not a plain name"),
    (("speed: [0.1, 0.2]", "params.a b: [1]"), "matrix.params.a b: 'a b' is not a ROS parameter name"),
    (("speed: [0.1, 0.2]", "params.x: [4294967296]"), "matrix.params.x[0]: 4294967296 does not fit"),
    (("speed: [0.1, 0.2]", "start: [{1: 2}]"), "matrix.start[0].1: 1 is not a target's name"),
    (("speed: [0.1, 0.2]", "speed: [0.1]\n  pair: [{speed: 0.3}]"), "matrix.pair[0].speed: sets speed, which"),
])
def test_bad_specs_are_refused_with_one_line_naming_the_key(write, change, key):
    with pytest.raises(SpecError) as error:
        load(write(GOOD.replace(*change)))
    message = str(error.value)
    assert "\n" not in message and key in message, message
    assert message.startswith(os.path.dirname(write(GOOD)))


def test_checks_need_finite_values_within_their_bounds():
    check = spec.Check(minimum=0.5, maximum=2.0)
    assert check.passes(0.5) and check.passes(2.0)
    assert not any(check.passes(value) for value in (0.49, 2.01, math.nan, math.inf))


def test_the_core_imports_no_ros():
    code = ("import sys; import mbot_batch.spec, mbot_batch.results, mbot_batch.report, mbot_batch.scenario; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('rospy', 'roslaunch', 'rosgraph')))")
    output = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert output.strip() == "[]"
