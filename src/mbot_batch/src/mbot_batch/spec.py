"""A batch spec (YAML), checked whole before anything starts and expanded into runs with stable ids.

    name: tour                          # optional; the output folder's default name
    scenarios:
      tour:
        launch: mbot_gazebo mbot_play_ground.launch   # "PACKAGE FILE" as roslaunch takes it, or a path
        args: {real_time_factor: 0}                    # fixed launch arguments
        python: tour_scenario.py                       # drives the run through the lockstep client
        metrics: {min_clearance: {min: 0.2}, distance: {min: 8.0}}
      bumper:
        rostest: mbot_tests bumper.test                # or a rostest file: its verdict counts
    matrix:                             # every combination of these runs (times repetitions)
      seed: {range: 5}                  # the simulator's seed
      args.real_time_factor: [0]        # a launch argument
      params./mbot/gain: [0.5, 1.0]     # a ROS parameter, set on the run's master before the launch
      speed: [0.2, 0.4]                 # a parameter the Python scenario reads (mbot_batch.scenario.parameters)
      start: {random_poses: {count: 20, seed: 1, x: [-1, 1], y: [-1, 1], Y: [-3.14, 3.14]}}
    repetitions: 1
    timeout: 120                        # wall seconds per run, start-up included
    retries: 1                          # for a run that crashed, hung or was killed

A matrix value may be a mapping of such targets set together (``random_poses`` makes mappings of ``args.x``,
``args.y`` and ``args.Y``). Free of ROS: launch files are resolved by the function the caller passes
(``launch_files.resolve`` with roslaunch).
"""
import hashlib
import json
import math
import os
import re
from dataclasses import asdict, dataclass, field
from itertools import product
from typing import Callable, Dict, List, Optional, Tuple

import yaml

TOP_KEYS = ("name", "scenarios", "matrix", "repetitions", "timeout", "retries")
SCENARIO_KEYS = ("launch", "python", "rostest", "args", "metrics")
CHECK_KEYS = ("min", "max")
GENERATORS = ("range", "random_poses")
POSE_AXES = ("x", "y", "Y")
# The arguments the batch itself gives every launch file: the run is stepped by its scenario and seeded.
BATCH_ARGS = ("lockstep", "seed")
DEFAULT_TIMEOUT = 300.0
# Bounds that keep a spec finishable: the driver holds one record per run (about 2 kB) and expands every run
# before the first starts; retries are for runs that crashed, not for a run that always does; a run longer than a
# day is a hang. Seeds and integer ROS parameters travel as XML-RPC's 32-bit integers.
MAX_RUNS = 100_000
MAX_RETRIES = 10
MAX_TIMEOUT = 86_400.0
MAX_SEED = 2**31 - 1
XMLRPC_INT = (-2**31, 2**31 - 1)
# Names that become folder names, Dask keys and parts of run ids.
PLAIN_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
# A global ROS name as the batch sets it (a leading / is added): letters first in every part.
ROS_NAME = re.compile(r"/?[A-Za-z]\w*(/[A-Za-z]\w*)*")


class SpecError(ValueError):
    """A spec that cannot run; the message is one line naming the file and the key."""


@dataclass(frozen=True)
class Check:
    minimum: Optional[float] = None
    maximum: Optional[float] = None

    def passes(self, value: float) -> bool:
        return (math.isfinite(value) and (self.minimum is None or value >= self.minimum)
                and (self.maximum is None or value <= self.maximum))

    def describe(self) -> str:
        bounds = [f">= {self.minimum:g}"] if self.minimum is not None else []
        return " and ".join(bounds + ([f"<= {self.maximum:g}"] if self.maximum is not None else []))


@dataclass(frozen=True)
class Scenario:
    name: str
    # As written in the spec (they make the run id) and as resolved (absolute paths, for running).
    definition: dict
    launch_path: Optional[str] = None
    python_path: Optional[str] = None
    rostest_path: Optional[str] = None
    args: Dict[str, str] = field(default_factory=dict)
    checks: Dict[str, Check] = field(default_factory=dict)
    declared_args: Tuple[str, ...] = ()


@dataclass
class Run:
    """One run: what the worker needs to run it, JSON round-trips through ``to_dict``/``from_dict``."""
    run_id: str
    scenario: str
    values: dict            # matrix key -> value, as in the spec
    labels: Dict[str, str]  # matrix key -> the value's short label (the report's axes)
    repetition: int
    seed: int
    launch_path: Optional[str]
    python_path: Optional[str]
    rostest_path: Optional[str]
    launch_args: Dict[str, str]
    ros_params: dict
    scenario_params: dict
    timeout: float

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> "Run":
        return cls(**data)


@dataclass
class Spec:
    path: str
    name: str
    scenarios: Dict[str, Scenario]
    matrix: Dict[str, list]
    repetitions: int
    timeout: float
    retries: int

    def runs(self) -> List[Run]:
        keys = list(self.matrix)
        runs = []
        for scenario in self.scenarios.values():
            for combination in product(*(range(len(self.matrix[key])) for key in keys)):
                values = {key: self.matrix[key][index] for key, index in zip(keys, combination)}
                labels = {key: _label(self.matrix[key], index) for key, index in zip(keys, combination)}
                for repetition in range(self.repetitions):
                    runs.append(self._run(scenario, values, labels, repetition))
        return runs

    def _run(self, scenario: Scenario, values: dict, labels: dict, repetition: int) -> Run:
        targets = {}
        for key, value in values.items():
            targets.update(value if isinstance(value, dict) else {key: value})
        seed = int(targets.pop("seed", 0))
        # Headless unless the spec says otherwise (a rerun's --gui turns the window on).
        launch_args = dict({"gui": "false"} if "gui" in scenario.declared_args else {}, **scenario.args)
        ros_params, scenario_params = {}, {}
        for target, value in targets.items():
            if target.startswith("args."):
                launch_args[target[len("args."):]] = _arg_text(value)
            elif target.startswith("params."):
                name = target[len("params."):]
                ros_params[name if name.startswith("/") else "/" + name] = value
            else:
                scenario_params[target] = value
        return Run(run_id=run_id(scenario.name, scenario.definition, values, repetition), scenario=scenario.name,
                   values=values, labels=labels, repetition=repetition, seed=seed,
                   launch_path=scenario.launch_path, python_path=scenario.python_path,
                   rostest_path=scenario.rostest_path, launch_args=launch_args, ros_params=ros_params,
                   scenario_params=scenario_params, timeout=self.timeout)


def run_id(scenario: str, definition: dict, values: dict, repetition: int) -> str:
    """``SCENARIO-HASH``: the same scenario (as written), matrix values (seed included) and repetition give the
    same id on any machine, in any order, whatever else the spec holds."""
    canonical = json.dumps({"scenario": scenario, "definition": definition, "values": values,
                            "repetition": repetition}, sort_keys=True, separators=(",", ":"))
    return f"{scenario}-{hashlib.sha256(canonical.encode()).hexdigest()[:12]}"


def _label(values: list, index: int) -> str:
    value = values[index]
    return f"#{index}" if isinstance(value, dict) else str(value)


def _arg_text(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    return repr(value) if isinstance(value, float) else str(value)


# A launch file resolver: (reference as written, the spec's folder, where) -> (absolute path, declared args).
Resolver = Callable[[str, str, str], Tuple[str, Tuple[str, ...]]]


def load(path: str, resolve_launch: Resolver) -> Spec:
    try:
        with open(path) as stream:
            data = yaml.safe_load(stream)
    except OSError as error:
        raise SpecError(f"{path}: cannot read: {error.strerror}") from None
    except yaml.YAMLError as error:
        raise SpecError(f"{path}: not YAML: {' '.join(str(error).split())}") from None
    return parse(data, path, resolve_launch)


def parse(data, path: str, resolve_launch: Resolver) -> Spec:
    where = _Where(path)
    if not isinstance(data, dict):
        where.fail("", "the spec must be a mapping with 'scenarios' and 'matrix'")
    where.known_keys("", data, TOP_KEYS)
    for required in ("scenarios", "matrix"):
        if required not in data:
            where.fail(required, "missing")
    folder = os.path.dirname(os.path.abspath(path))
    scenarios_data = data["scenarios"]
    if not isinstance(scenarios_data, dict) or not scenarios_data:
        where.fail("scenarios", "must map at least one scenario name to its definition")
    scenarios = {_plain(name, f"scenarios.{name}", where): _scenario(str(name), definition, folder, where,
                                                                      resolve_launch)
                 for name, definition in scenarios_data.items()}
    matrix = _matrix(data["matrix"], where)
    setters = {}
    for key, values in matrix.items():
        for index, value in enumerate(values):
            for target, entry in (value if isinstance(value, dict) else {key: value}).items():
                if isinstance(value, dict):
                    target_key = value_key = f"matrix.{key}[{index}].{target}"
                else:
                    target_key, value_key = f"matrix.{key}", f"matrix.{key}[{index}]"
                _check_target(target, entry, scenarios, where, target_key, value_key)
                if setters.setdefault(target, key) != key:
                    where.fail(target_key, f"sets {target}, which matrix.{setters[target]} sets too")
    repetitions = _integer(data.get("repetitions", 1), "repetitions", 1, where, MAX_RUNS)
    count = len(scenarios) * repetitions * math.prod(len(values) for values in matrix.values())
    if count > MAX_RUNS:
        where.fail("matrix", f"makes {count} runs, more than the {MAX_RUNS} a batch may hold")
    name = data.get("name") or os.path.splitext(os.path.basename(path))[0]
    return Spec(path=path, name=_plain(name, "name", where), scenarios=scenarios, matrix=matrix,
                repetitions=repetitions, timeout=_positive(data.get("timeout", DEFAULT_TIMEOUT), "timeout", where),
                retries=_integer(data.get("retries", 0), "retries", 0, where, MAX_RETRIES))


class _Where:
    def __init__(self, path: str):
        self.path = path

    def fail(self, key: str, problem: str):
        raise SpecError(f"{self.path}: {key}: {problem}" if key else f"{self.path}: {problem}")

    def known_keys(self, key: str, mapping: dict, known):
        for name in mapping:
            if name not in known:
                self.fail(f"{key}.{name}" if key else str(name), f"unknown key (known: {', '.join(known)})")


def _scenario(name, definition, folder, where: _Where, resolve_launch: Resolver) -> Scenario:
    key = f"scenarios.{name}"
    if not isinstance(definition, dict):
        where.fail(key, "must be a mapping (launch + python, or rostest)")
    where.known_keys(key, definition, SCENARIO_KEYS)
    if ("python" in definition) == ("rostest" in definition):
        where.fail(key, "needs exactly one of 'python' (with 'launch') or 'rostest'")
    launch_path = rostest_path = python_path = None
    declared = ()
    if "python" in definition:
        if "launch" not in definition:
            where.fail(f"{key}.launch", "missing: a Python scenario drives a launch file's simulation")
        launch_path, declared = resolve_launch(_text(definition["launch"], f"{key}.launch", where), folder,
                                               f"{where.path}: {key}.launch")
        python_path = os.path.join(folder, _text(definition["python"], f"{key}.python", where))
        if not os.path.isfile(python_path):
            where.fail(f"{key}.python", f"no such file: {python_path}")
    else:
        if "launch" in definition:
            where.fail(f"{key}.launch", "a rostest scenario's test file is its launch file")
        rostest_path, declared = resolve_launch(_text(definition["rostest"], f"{key}.rostest", where), folder,
                                                f"{where.path}: {key}.rostest")
    for argument in BATCH_ARGS:
        if argument not in declared:
            where.fail(key, f"{os.path.basename(launch_path or rostest_path)} declares no '{argument}' argument, "
                            "which every run sets (lockstep:=true, seed:=N)")
    args = definition.get("args") or {}
    if not isinstance(args, dict):
        where.fail(f"{key}.args", "must map launch argument names to values")
    for argument, value in args.items():
        _scalar(value, f"{key}.args.{argument}", where)
        if argument not in declared:
            where.fail(f"{key}.args.{argument}", f"not an argument of the launch file (it takes {', '.join(declared)})")
        if argument in BATCH_ARGS:
            where.fail(f"{key}.args.{argument}", "set by the batch for every run")
    metrics = definition.get("metrics") or {}
    if not isinstance(metrics, dict):
        where.fail(f"{key}.metrics", "must map metric names to {min, max}")
    checks = {}
    for metric, bounds in metrics.items():
        if not isinstance(bounds, dict) or not bounds:
            where.fail(f"{key}.metrics.{metric}", "must be a mapping with min and/or max")
        where.known_keys(f"{key}.metrics.{metric}", bounds, CHECK_KEYS)
        check = Check(*(None if bounds.get(bound) is None else
                        _finite(bounds[bound], f"{key}.metrics.{metric}.{bound}", where) for bound in CHECK_KEYS))
        if check.minimum is not None and check.maximum is not None and check.minimum > check.maximum:
            where.fail(f"{key}.metrics.{metric}", f"min {check.minimum:g} is above max {check.maximum:g}: "
                                                  "no value can pass")
        checks[str(metric)] = check
    written = {name: definition[name] for name in ("launch", "python", "rostest", "args") if name in definition}
    return Scenario(name=name, definition=written, launch_path=launch_path, python_path=python_path,
                    rostest_path=rostest_path, args={k: _arg_text(v) for k, v in args.items()}, checks=checks,
                    declared_args=tuple(declared))


def _matrix(data, where: _Where) -> Dict[str, list]:
    if not isinstance(data, dict) or not data:
        where.fail("matrix", "empty: give at least one key with values (seed: [0] for a single run)")
    matrix = {}
    for key, values in data.items():
        key = str(key)
        if isinstance(values, dict):
            values = _generated(values, f"matrix.{key}", where)
        if not isinstance(values, list) or not values:
            where.fail(f"matrix.{key}", "needs a non-empty list of values (or range / random_poses)")
        for index, value in enumerate(values):
            if isinstance(value, dict):
                if not value:
                    where.fail(f"matrix.{key}[{index}]", "an empty mapping")
                for target, entry in value.items():
                    _scalar(entry, f"matrix.{key}[{index}].{target}", where)
            else:
                _scalar(value, f"matrix.{key}[{index}]", where)
        matrix[key] = values
    return matrix


def _generated(generator: dict, key: str, where: _Where) -> list:
    if len(generator) != 1 or next(iter(generator)) not in GENERATORS:
        where.fail(key, f"a mapping of values must be one generator: {' or '.join(GENERATORS)}")
    kind, options = next(iter(generator.items()))
    if kind == "range":
        bounds = options if isinstance(options, list) else [options]
        if not 1 <= len(bounds) <= 3 or not all(isinstance(b, int) and not isinstance(b, bool) for b in bounds):
            where.fail(f"{key}.range", "takes N, [START, STOP] or [START, STOP, STEP] (integers)")
        start, stop, step = (0, bounds[0], 1) if len(bounds) == 1 else (*bounds, 1)[:3]
        if step == 0:
            where.fail(f"{key}.range", "a step of 0 never reaches its stop")
        # Counted before it is made: len() of a range past sys.maxsize raises.
        if (stop - start + step - (1 if step > 0 else -1)) // step > MAX_RUNS:
            where.fail(f"{key}.range", f"more than the {MAX_RUNS} runs a batch may hold")
        return list(range(start, stop, step))
    if not isinstance(options, dict):
        where.fail(f"{key}.random_poses", "takes count, seed and [low, high] for x, y and Y")
    where.known_keys(f"{key}.random_poses", options, ("count", "seed") + POSE_AXES)
    count = _integer(options.get("count"), f"{key}.random_poses.count", 1, where, MAX_RUNS)
    seed = _integer(options.get("seed", 0), f"{key}.random_poses.seed", 0, where)
    ranges = {}
    for axis in POSE_AXES:
        bounds = options.get(axis, [0.0, 0.0])
        if not isinstance(bounds, list) or len(bounds) != 2:
            where.fail(f"{key}.random_poses.{axis}", "takes [low, high]")
        low, high = (_finite(b, f"{key}.random_poses.{axis}", where) for b in bounds)
        if low > high:
            where.fail(f"{key}.random_poses.{axis}", f"low {low:g} is above high {high:g}")
        ranges[axis] = (low, high)
    # numpy's generator is stable for a seed across versions (NEP 19: PCG64 streams are kept); rounded to
    # millimetres and milliradians so that the launch arguments are short and read back exactly.
    import numpy
    generator = numpy.random.default_rng(seed)
    return [{f"args.{axis}": round(float(generator.uniform(*ranges[axis])), 3) for axis in POSE_AXES}
            for _ in range(count)]


def _check_target(target, value, scenarios: Dict[str, Scenario], where: _Where, key: str, value_key: str):
    """``key`` names the target in the spec, ``value_key`` the value."""
    if not isinstance(target, str):
        where.fail(key, f"{target!r} is not a target's name (seed, args.NAME, params.NAME or a scenario parameter)")
    if target == "seed":
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_SEED:
            where.fail(value_key, f"a seed must be an integer from 0 to {MAX_SEED}, not {value!r}")
        return
    if target.startswith("args."):
        name = target[len("args."):]
        if name in BATCH_ARGS:
            where.fail(key, f"'{name}' is set by the batch for every run")
        for scenario in scenarios.values():
            if name not in scenario.declared_args:
                where.fail(key, f"scenario '{scenario.name}''s launch file has no argument '{name}' "
                                f"(it takes {', '.join(scenario.declared_args)})")
    elif target.startswith("params."):
        if not ROS_NAME.fullmatch(target[len("params."):]):
            where.fail(key, f"'{target[len('params.'):]}' is not a ROS parameter name")
        if isinstance(value, int) and not isinstance(value, bool) and not XMLRPC_INT[0] <= value <= XMLRPC_INT[1]:
            where.fail(value_key, f"{value} does not fit a ROS parameter's 32-bit integer")


def _plain(name, key: str, where: _Where) -> str:
    if not isinstance(name, (str, int)) or isinstance(name, bool) or not PLAIN_NAME.fullmatch(str(name)):
        where.fail(key, f"{name!r} is not a plain name (letters, digits, '_', '.' and '-'; it names folders)")
    return str(name)


def _text(value, key: str, where: _Where) -> str:
    if not isinstance(value, str) or not value.strip():
        where.fail(key, "must be a non-empty text")
    return value.strip()


def _scalar(value, key: str, where: _Where):
    if isinstance(value, bool) or isinstance(value, (int, str)):
        return value
    if isinstance(value, float):
        return _finite(value, key, where)
    where.fail(key, f"must be a number, text or boolean, not {type(value).__name__}")


def _finite(value, key: str, where: _Where) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        where.fail(key, f"must be a number, not {value!r}")
    if not math.isfinite(value):
        where.fail(key, f"{value!r} is not a usable value (NaN and infinities are refused)")
    return float(value)


def _positive(value, key: str, where: _Where) -> float:
    seconds = _finite(value, key, where)
    if not 0 < seconds <= MAX_TIMEOUT:
        where.fail(key, f"must be a positive number of seconds up to {MAX_TIMEOUT:g}, not {value!r}")
    return seconds


def _integer(value, key: str, minimum: int, where: _Where, maximum: int = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        where.fail(key, f"must be an integer >= {minimum}, not {value!r}")
    if maximum is not None and value > maximum:
        where.fail(key, f"must be at most {maximum}, not {value}")
    return value
