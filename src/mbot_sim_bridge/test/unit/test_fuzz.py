"""Fuzzing the core with Hypothesis: malformed robot descriptions and worlds (mutations of the shipped ones) and
garbage service-like requests. Each case must be loaded, or refused with one line (a BridgeError without a
newline); never another exception, a hang, a plugin that fails while stepping, or a NaN state.

Hypothesis runs with a fixed seed and no example database; the outcome counts are printed as "figure:" lines.
"""
import copy
import logging
import math
import os
import re
import resource
import signal
import tempfile
from collections import Counter
from contextlib import contextmanager
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.errors import BridgeError
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.description.model_path import default_model_path
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_spawn import read_spawned_model, spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.robot_description import expand_xacro

HERE = os.path.dirname(os.path.abspath(__file__))
WORLDS = os.path.join(HERE, "..", "..", "..", "..", "worlds")
TEST_WORLDS = os.path.join(HERE, "..", "worlds")
# One case may take this long (a spawn, a world load, a few hundred steps) before it counts as a hang.
CASE_SECONDS = 10.0
STEPS = 200
MEMORY_LIMIT_BYTES = 6 << 30
FUZZ = settings(derandomize=True, deadline=None, database=None, print_blob=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])

# Finite but extreme: the smallest normal and subnormal doubles and the largest magnitudes.
EXTREMES = ("1e-308", "5e-324", "-5e-324", "1e308", "-1e308")
BAD_NUMBERS = ("nan", "NaN", "-nan", "inf", "-inf", "1e309", "-1e309", "1e300", "-1e300", "1e-300", "0", "-0",
               "-1", "-1000", "1e5", "1e12", "99999999999999999999", "0x10", "abc", "", " ", "1 2 3",
               "true") + EXTREMES
BAD_VECTORS = ("nan 0 0", "0 0 inf", "1e300 0 0", "0 0", "1 2 3 4 5 6 7", "-1 -1 -1", "0 0 0", "a b c",
               "1e-300 1e-300 1e-300", "nan 0 1 0 0 0", "0 0 0 0 0 1e300", "1e-308 0 0", "5e-324 0 0",
               "0 5e-324 5e-324", "1e308 1e308 1e308")
# MBOT_FULL_SWEEP=1 runs every case of the sweeps below and the larger draws; otherwise a seeded sample, for the
# suite's time (the sample is the first draws of the same seeded sequence).
FULL_SWEEP = bool(os.environ.get("MBOT_FULL_SWEEP"))


def draws(in_the_suite: int, full: int) -> int:
    return full if FULL_SWEEP else in_the_suite
# A dynamic crate beside each case; it must not move by more than this (m).
BYSTANDER_TOLERANCE = 1e-4
MESHES = ("/nonexistent/mesh.stl", "/dev/null", "/tmp", "meshes/relative.stl", "package://nowhere/m.stl",
          "http://example.invalid/m.stl", "file:///nonexistent.dae", "model://nowhere/mesh.dae")

# Elements whose text names another element or a file.
REFERENCE_TAGS = ("leftJoint", "rightJoint", "jointName", "uri", "relative_to", "frameName", "bodyName")

OUTCOMES = {}


class Hang(Exception):
    pass


@contextmanager
def watchdog(seconds=CASE_SECONDS):
    """Interrupts a case that blocks (a FIFO read, an endless loop in Python) by raising Hang."""
    def expire(*_):
        raise Hang(f"case did not finish within {seconds:.0f} s")
    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def tally(kind, outcome):
    OUTCOMES.setdefault(kind, Counter())[outcome] += 1


def refused(kind, error):
    message = str(error)
    assert message and "\n" not in message, f"a refusal must be one line: {message!r}"
    tally(kind, f"refused ({type(error).__name__})")


@pytest.fixture(scope="module", autouse=True)
def print_outcomes():
    # A case that asks for absurd memory fails here with MemoryError instead of starving the machine.
    limits = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT_BYTES, limits[1]))
    # The mbot's <rosDebugLevel>Debug</rosDebugLevel> sets the bridge's log level, for the tests after these too.
    bridge_logger = logging.getLogger("rosout.mbot_sim_bridge")
    level = bridge_logger.level
    yield
    bridge_logger.setLevel(level)
    resource.setrlimit(resource.RLIMIT_AS, limits)
    for kind, counts in OUTCOMES.items():
        details = ", ".join(f"{count} {outcome}" for outcome, count in sorted(counts.items()))
        print(f"figure: fuzz {kind}: {sum(counts.values())} cases: {details}")
    for kind in MIXED_OUTCOMES:
        if kind in OUTCOMES:  # a run narrowed with -k may leave a fuzzer out
            assert_outcome_mix(kind, OUTCOMES[kind])


# The fuzzers whose draws must be partly refused and partly carried out (the extreme-value, link-count and gripper
# sweeps walk fixed lists whose outcomes their own tests check).
MIXED_OUTCOMES = ("robot descriptions", "worlds", "service requests", "hostile structures")
# The request kinds some generated requests carry out. Not spawn_sdf: its one valid model with seven finite numbers
# is rare among the draws (none in 150 sequences with the fixed seed).
REQUEST_KINDS = ("set_model_state", "spawn_robot", "delete", "command", "reset_world", "reset_simulation")


def assert_outcome_mix(kind, counts):
    """Fuzzing reaches the engine only through cases that are not refused: a regression refusing every case (or
    none) would pass the per-case checks, so some of each must occur, and every request kind must get through."""
    refusals = sum(count for outcome, count in counts.items() if outcome.startswith("refused"))
    assert 0 < refusals < sum(counts.values()), f"fuzz {kind}: {dict(counts)}"
    if kind == "service requests":
        assert all(counts[f"done ({request})"] > 0 for request in REQUEST_KINDS), f"fuzz {kind}: {dict(counts)}"


# -- mutations ----------------------------------------------------------------------------------------------------
def _parents(root):
    return {child: parent for parent in root.iter() for child in parent}


def mutate(data, root, reference_attributes):
    """One random damage to the XML tree ``root``."""
    parents = _parents(root)
    elements = [element for element in root.iter() if element is not root]
    if not elements:
        root.text = data.draw(st.sampled_from(BAD_NUMBERS))
        return
    kind = data.draw(st.sampled_from(("delete", "text", "attribute", "reference", "duplicate", "mesh")))
    element = data.draw(st.sampled_from(elements))
    if kind == "delete":
        parents[element].remove(element)
    elif kind == "text":
        leaves = [e for e in elements if len(e) == 0] or elements
        target = data.draw(st.sampled_from(leaves))
        target.text = data.draw(st.sampled_from(BAD_NUMBERS + BAD_VECTORS) | st.floats().map(repr)
                                | st.text(max_size=8))
    elif kind == "attribute":
        with_attributes = [(e, name) for e in elements for name in e.attrib] or [(element, "name")]
        target, name = data.draw(st.sampled_from(with_attributes))
        target.set(name, data.draw(st.sampled_from(BAD_NUMBERS + BAD_VECTORS) | st.text(max_size=8)))
    elif kind == "reference":
        candidates = [(e, name) for e in elements for name in e.attrib if name in reference_attributes]
        candidates += [(e, None) for e in elements if e.tag in REFERENCE_TAGS]
        if candidates:
            target, name = data.draw(st.sampled_from(candidates))
            broken = data.draw(st.sampled_from(("nowhere", "", "model://nowhere", "base_link", "world")))
            if name is None:
                target.text = broken
            else:
                target.set(name, broken)
    elif kind == "duplicate":
        parents[element].append(copy.deepcopy(element))
    else:
        geometries = [e for e in elements if e.tag == "geometry"]
        if geometries:
            geometry = data.draw(st.sampled_from(geometries))
            for child in list(geometry):
                geometry.remove(child)
            mesh = ET.SubElement(geometry, "mesh", filename=data.draw(st.sampled_from(MESHES)))
            ET.SubElement(mesh, "uri").text = mesh.get("filename")


# -- states -------------------------------------------------------------------------------------------------------
def assert_finite_state(sim, label):
    for name in sim.model_names():
        pose = sim.engine.model_pose(name)
        linear, angular = sim.engine.model_velocity(name)
        values = tuple(pose.position) + tuple(pose.orientation) + tuple(linear) + tuple(angular)
        assert all(math.isfinite(v) for v in values), f"{label}: model '{name}' has a non-finite state {values}"
    for spawned in sim.models.values():
        robot = spawned.robot
        for position, velocity, _ in robot.joint_state(list(robot.movable_joints)):
            assert math.isfinite(position) and math.isfinite(velocity), f"{label}: '{spawned.name}' joints"


def step_and_check(sim, label, command=(0.5, 1.0)):
    plugins = {name: list(spawned.plugins) for name, spawned in sim.models.items()}
    for spawned in sim.models.values():
        for plugin in spawned.plugins:
            if isinstance(plugin, DiffDrive):
                plugin.set_command(*command)
    sim.step(STEPS)
    assert_finite_state(sim, label)
    for name, spawned in sim.models.items():
        # A plugin that failed was disabled by the loop's guard: the validation let a bad value through.
        assert spawned.plugins == plugins[name], f"{label}: a plugin of '{name}' failed while stepping"
        for plugin in spawned.plugins:
            if isinstance(plugin, DiffDrive):
                values = np.hstack([np.ravel(part) for part in plugin.odometry()[0]] + list(plugin.odometry()[1:]))
                assert np.all(np.isfinite(values)), f"{label}: odometry {values}"


# -- robot descriptions -------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def simulation():
    sim = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), CORE_PLUGINS)
    yield sim
    sim.close()


@pytest.fixture(scope="module")
def fifo():
    directory = tempfile.mkdtemp(prefix="mbot_fuzz_")
    path = os.path.join(directory, "mesh.stl")
    os.mkfifo(path)
    yield path
    os.unlink(path)
    os.rmdir(directory)


@settings(FUZZ, max_examples=draws(80, 250))
@given(data=st.data())
def test_malformed_robot_descriptions(data, laser_mbot_urdf, simulation, fifo):
    root = ET.fromstring(laser_mbot_urdf)
    for _ in range(data.draw(st.integers(1, 3))):
        mutate(data, root, ("link", "reference", "joint", "name"))
    if data.draw(st.integers(0, 19)) == 0:
        # A mesh that is a FIFO: reading it would block for ever.
        geometry = root.find("link/collision/geometry")
        if geometry is not None:
            for child in list(geometry):
                geometry.remove(child)
            ET.SubElement(geometry, "mesh", filename=fifo)
    xml = ET.tostring(root, encoding="unicode")
    try:
        with watchdog():
            model = parse_robot(xml, "model 'fuzz'")
            simulation.spawn_robot(model, "fuzz")
    except BridgeError as error:
        assert "fuzz" not in simulation.model_names(), "a refused model was left behind"
        refused("robot descriptions", error)
        return
    try:
        with watchdog():
            step_and_check(simulation, "mutated robot")
        tally("robot descriptions", "loaded")
    finally:
        simulation.delete("fuzz")


# -- worlds -------------------------------------------------------------------------------------------------------
WORLD_BASES = [os.path.join(WORLDS, name) for name in ("playground.world", "room.world", "empty.world")] + [
    os.path.join(TEST_WORLDS, name) for name in ("dynamics.world", "include.world", "meshes.world",
                                                 "nested_poses.world", "relative_to.world", "friction.world")]


@pytest.fixture(scope="module")
def world_directory():
    """A scratch folder beside which the test worlds' relative meshes resolve as they do from test/worlds."""
    directory = tempfile.mkdtemp(prefix="mbot_fuzz_worlds_")
    os.symlink(os.path.join(TEST_WORLDS, "meshes"), os.path.join(directory, "meshes"))
    yield directory
    for name in os.listdir(directory):
        os.unlink(os.path.join(directory, name))
    os.rmdir(directory)


@settings(FUZZ, max_examples=draws(40, 120))
@given(data=st.data())
def test_malformed_worlds(data, world_directory):
    base = data.draw(st.sampled_from(WORLD_BASES))
    root = ET.parse(base).getroot()
    for _ in range(data.draw(st.integers(1, 3))):
        mutate(data, root, ("name", "relative_to", "attached_to"))
    path = os.path.join(world_directory, "fuzz.world")
    with open(path, "w") as world_file:
        world_file.write(ET.tostring(root, encoding="unicode"))
    model_path = default_model_path() + [os.path.join(TEST_WORLDS, "models")]
    try:
        with watchdog():
            world = parse_world(path, model_path)
            sim = Simulation(world, CORE_PLUGINS)
    except BridgeError as error:
        refused("worlds", error)
        return
    try:
        with watchdog():
            step_and_check(sim, f"mutated {os.path.basename(base)}")
        tally("worlds", "loaded")
    finally:
        sim.close()


# -- service-like requests ----------------------------------------------------------------------------------------
# Mostly plausible values, so that requests get past the checks and the engine is exercised too.
NUMBERS = st.one_of(st.floats(-10, 10), st.floats(-10, 10), st.floats(allow_nan=True, allow_infinity=True),
                    st.sampled_from((0.0, -0.0, 1e5, -1e5, 1e4, -1e4, 1e-300)))
VECTOR = st.tuples(NUMBERS, NUMBERS, NUMBERS)
QUATERNION = st.tuples(NUMBERS, NUMBERS, NUMBERS, NUMBERS)
# Names with line breaks are left out: the node's name check refuses them for spawns, and messages about them
# (model 'a<newline>b' does not exist) would span lines.
NAMES = st.sampled_from(("mbot", "ground_plane", "nowhere", "", "mbot/", "MBOT")) | st.text(
    st.characters(blacklist_categories=("Cc", "Cs", "Zl", "Zp")), max_size=6)


def service_pose(position, quaternion):
    """The pose a gazebo_msgs request turns into (services.py): its quaternion normalised, zero = identity.
    hypot, not a sum of squares: a component above 1.3e154 squares to inf, which would normalise to zeros."""
    norm = math.hypot(*quaternion)
    if norm == 0:
        return Pose(position, (0.0, 0.0, 0.0, 1.0))
    return Pose(position, tuple(v / norm for v in quaternion))


@pytest.fixture(scope="module")
def mbot_model(mbot_urdf):
    return parse_robot(mbot_urdf, "model 'mbot'")


EXTREME_NUMBERS = st.sampled_from(tuple(float(text) for text in EXTREMES) + (0.0, -1.0, 1.0))
INERTIAL_SDF = ("<sdf version='1.6'><model name='m'><link name='l'><inertial><mass>{}</mass><inertia><ixx>{}</ixx>"
                "<iyy>{}</iyy><izz>{}</izz></inertia></inertial><collision name='c'><geometry><box><size>0.5 0.5 0.5"
                "</size></box></geometry></collision></link></model></sdf>")

REQUESTS = st.one_of(
    st.tuples(st.just("set_model_state"), NAMES, VECTOR, QUATERNION, VECTOR, VECTOR),
    st.tuples(st.just("spawn_sdf"), st.just("crate"), st.just((3.0, 0.0, 0.3)), st.just((0.0, 0.0, 0.0, 1.0)),
              st.tuples(EXTREME_NUMBERS, EXTREME_NUMBERS, EXTREME_NUMBERS, EXTREME_NUMBERS).map(
                  lambda values: INERTIAL_SDF.format(*values))),
    st.tuples(st.just("step"), st.sampled_from((1, 100, 2000))),
    st.tuples(st.just("wrench"), st.sampled_from(("mbot::base_footprint", "crate::l", "nowhere::l")), VECTOR,
              EXTREME_NUMBERS, EXTREME_NUMBERS),
    st.tuples(st.just("spawn_robot"), NAMES, VECTOR, QUATERNION),
    st.tuples(st.just("spawn_sdf"), NAMES, VECTOR, QUATERNION,
              st.sampled_from(("<sdf version='1.6'><model name='m'><link name='l'><collision name='c'><geometry>"
                               "<box><size>1 1 1</size></box></geometry></collision></link></model></sdf>",
                               f"<sdf><model name='m'><pose>{BAD_VECTORS[0]}</pose></model></sdf>",
                               "<robot name='r'/>", "", "<sdf>", "<sdf version='1.6'><world name='w'/></sdf>"))),
    st.tuples(st.just("delete"), NAMES),
    st.tuples(st.just("command"), NUMBERS, NUMBERS),
    st.tuples(st.sampled_from(("reset_world", "reset_simulation"))),
)


def _apply(sim, request, mbot_urdf):
    name = request[0]
    if name == "set_model_state":
        _, model, position, quaternion, linear, angular = request
        sim.engine.set_model_state(model, service_pose(position, quaternion), linear, angular)
    elif name == "spawn_robot":
        _, model, position, quaternion = request
        sim.spawn_robot(parse_robot(mbot_urdf, f"model '{model}'"), model, service_pose(position, quaternion))
    elif name == "spawn_sdf":
        _, model, position, quaternion, xml = request
        world_xml = spawn_world_xml(xml, model, service_pose(position, quaternion))
        with tempfile.NamedTemporaryFile("w", suffix=".world") as world_file:
            world_file.write(world_xml)
            world_file.flush()
            sim.add_world(parse_world(world_file.name))
    elif name == "delete":
        sim.delete(request[1])
    elif name == "step":
        sim.step(request[1])
    elif name == "wrench":
        _, body, force, start, duration = request
        sim.apply_body_wrench(body, "", (0.0, 0.0, 0.0), force, (0.0, 0.0, 0.0), start, duration)
    elif name == "command":
        for spawned in sim.models.values():
            for plugin in spawned.plugins:
                if isinstance(plugin, DiffDrive):
                    plugin.set_command(request[1], request[2])
    else:
        sim.reset(simulation=name == "reset_simulation")


@settings(FUZZ, max_examples=draws(30, 150))
@given(requests=st.lists(REQUESTS, min_size=1, max_size=4))
# Found: a wrench starting at 1e308 s overflowed the loop's count of steps to its start.
@example(requests=[("wrench", "mbot::base_footprint", (1.0, 0.0, 0.0), 1e308, 1.0), ("step", 100)])
# Every request kind carried out once, so that the outcome mix holds in the suite's smaller sample too.
@example(requests=[("spawn_robot", "second", (2.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
                   ("set_model_state", "second", (2.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0),
                    (0.0, 0.0, 0.0)),
                   ("command", 0.2, 0.0), ("step", 100), ("reset_world",), ("reset_simulation",), ("delete", "second")])
def test_garbage_requests(requests, mbot_model, mbot_urdf):
    """A fresh world with the mbot for each sequence, so that a failure shrinks to the requests that made it."""
    sim = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), CORE_PLUGINS)
    try:
        sim.spawn_robot(mbot_model, "mbot")
        for request in requests:
            try:
                with watchdog():
                    _apply(sim, request, mbot_urdf)
                tally("service requests", f"done ({request[0]})")
            except BridgeError as error:
                refused("service requests", error)
        with watchdog():
            sim.step(STEPS // 4)
            assert_finite_state(sim, f"after {requests}")
            # Whatever the requests did, reset_world brings every model back to a finite spawn state.
            sim.reset(simulation=False)
            sim.step(10)
            assert_finite_state(sim, f"reset after {requests}")
    finally:
        sim.close()


# -- what the fuzzing found, kept as plain cases ------------------------------------------------------------------
def _laser_mbot_with(urdf, edit):
    root = ET.fromstring(urdf)
    edit(root)
    return ET.tostring(root, encoding="unicode")


def _duplicate_joint(root):
    root.append(copy.deepcopy(root.find("joint[@name='left_wheel_joint']")))


def _empty_geometry(root):
    geometry = root.find("link[@name='left_wheel_link']/collision/geometry")
    for child in list(geometry):
        geometry.remove(child)


def _second_parent(root):
    joint = copy.deepcopy(root.find("joint[@name='lidar_joint']"))
    joint.set("name", "second_lidar_joint")
    joint.find("parent").set("link", "left_wheel_link")
    root.append(joint)


@pytest.mark.parametrize("edit, expected", [
    # PyBullet crashed the whole process (segmentation fault).
    (_duplicate_joint, "joint 'left_wheel_joint': defined twice"),
    # PyBullet: "Cannot load URDF file", naming nothing.
    (lambda root: root.append(copy.deepcopy(root.find("link[@name='laser_link']"))),
     "link 'laser_link' is defined twice"),
    (_empty_geometry, "link 'left_wheel_link' collision <geometry> needs one shape"),
    # Loaded silently, one of the two parents dropped.
    (_second_parent, "child link 'laser_link' already has a parent joint, 'lidar_joint'"),
    # Absurd shapes and inertials went into the physics (a mass of 1e300 gives a NaN pose).
    (lambda root: root.find("link[@name='base_link']/collision/geometry/cylinder").set("radius", "-0.16"),
     "link 'base_link' collision <cylinder radius>: -0.16 is outside the valid range > 0"),
    (lambda root: root.find("link[@name='base_link']/inertial/inertia").set("ixx", "-1"),
     "link 'base_link': <inertia ixx>: -1 is outside the valid range >= 0"),
    (lambda root: root.find("link[@name='base_link']/inertial/mass").set("value", "1e300"),
     "link 'base_link': <mass value>: 1e+300 is outside the valid range 0 or >= 1e-06 and <= 1e+09"),
    # 36 million rays per scan took the machine's memory.
    (lambda root: setattr(root.find(".//sensor/ray/scan/horizontal/resolution"), "text", "1e5"),
     "3.6e+07 ranges per scan; at most 262144 are simulated"),
])
def test_found_by_fuzzing(laser_mbot_urdf, simulation, edit, expected):
    with pytest.raises(BridgeError) as error:
        with watchdog():
            simulation.spawn_robot(parse_robot(_laser_mbot_with(laser_mbot_urdf, edit), "model 'fuzz'"), "fuzz")
    assert expected in str(error.value) and "\n" not in str(error.value)
    assert "fuzz" not in simulation.model_names()


def test_a_bad_visual_is_left_out(laser_mbot_urdf, simulation, caplog):
    def bad_visual(root):
        root.find("link[@name='base_link']/visual/geometry/cylinder").set("length", "nan")
    spawned = simulation.spawn_robot(parse_robot(_laser_mbot_with(laser_mbot_urdf, bad_visual), "model 'seen'"), "seen")
    try:
        assert "model 'seen': link 'base_link' visual <cylinder length>: NaN is not a valid value" in caplog.text
        assert "the visual is left out" in caplog.text
        assert spawned.plugins
    finally:
        simulation.delete("seen")


# -- extreme finite values in every numeric tag of every plugin and sensor the test robots carry --------------------
def host_robots(laser_mbot_urdf):
    """Robots that carry between them every emulated plugin but gazebo_ros_control (its one number, controlPeriod,
    is a period() like the hector one's): their descriptions by name."""
    from plugin_robots import (HOLONOMIC_XACRO, MIMIC_GRIPPER, MIMIC_PLUGIN_BLOCK, SKID_XACRO, STEREO_XACRO,
                               TRICYCLE_XACRO, VELODYNE_STAND)
    from sensor_fixtures import course_urdf
    from test_new_plugin_inputs import SENSOR_ROBOTS, VLP16_MACRO
    directory = tempfile.mkdtemp(prefix="mbot_fuzz_hosts_")
    stand = os.path.join(directory, "stand.urdf.xacro")
    with open(stand, "w") as stand_file:
        stand_file.write(VELODYNE_STAND.format(macro=VLP16_MACRO, noise=0.008, organize="false"))
    def small_images(urdf):  # a case renders a dozen frames: at 1280 x 720 they outlast the watchdog
        return re.sub(r"<height>\d+</height>", "<height>48</height>",
                      re.sub(r"<width>\d+</width>", "<width>64</width>", urdf))
    hosts = {"laser mbot": laser_mbot_urdf, "camera mbot": small_images(course_urdf("mbot_with_camera_gazebo")),
             "kinect mbot": small_images(course_urdf("mbot_with_kinect_gazebo")),
             "planar": expand_xacro(HOLONOMIC_XACRO),
             "skid": expand_xacro(SKID_XACRO),
             "tricycle": expand_xacro(TRICYCLE_XACRO),
             "stereo head": small_images(expand_xacro(STEREO_XACRO, rate="50")),
             # 40 of the VLP-16's 440 columns: at an extreme update_rate it scans every step.
             "velodyne": expand_xacro(stand).replace("<samples>440</samples>", "<samples>40</samples>"),
             "gripper": MIMIC_GRIPPER.format(mimic="", plugin=MIMIC_PLUGIN_BLOCK.format(extra="")), **SENSOR_ROBOTS}
    os.unlink(stand)
    os.rmdir(directory)
    return hosts


def numeric_tag_cases(hosts):
    """(host, plugin index, tag, on the sensor) for every int or float tag of every plugin's and sensor's table."""
    cases = []
    for host, urdf in hosts.items():
        root = ET.fromstring(urdf)
        parents = _parents(root)
        for index, plugin in enumerate(root.iter("plugin")):
            plugin_class = CORE_PLUGINS.get(plugin.get("filename", ""))
            if plugin_class is None:
                continue
            on_sensor = parents[plugin].tag == "sensor"
            for params, sensor_side in ((plugin_class.PARAMS, False), (plugin_class.SENSOR_PARAMS, True)):
                cases += [(host, index, param.tag, sensor_side) for param in params
                          if param.kind in (int, float) and (on_sensor or not sensor_side)]
    return cases


@pytest.fixture(scope="module")
def tag_cases(laser_mbot_urdf):
    hosts = host_robots(laser_mbot_urdf)
    return hosts, numeric_tag_cases(hosts)


def with_tag(urdf, index, tag, on_sensor, text):
    root = ET.fromstring(urdf)
    plugin = list(root.iter("plugin"))[index]
    element = _parents(root)[plugin] if on_sensor else plugin
    for part in tag.split("/"):
        child = element.find(part)
        element = child if child is not None else ET.SubElement(element, part)
    element.text = text
    return ET.tostring(root, encoding="unicode")


CRATE = ("<robot name='crate'><link name='crate'><inertial><mass value='1'/><inertia ixx='0.01' iyy='0.01' "
         "izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial><collision><geometry><box size='0.3 0.3 0.3'/></geometry>"
         "</collision></link></robot>")


def spawn_beside_a_crate(kind, urdf, steps=100):
    """Spawn ``urdf`` 3 m from a settled crate and step: loaded (finite, no plugin failed, the crate still) or
    refused with one line."""
    sim = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), CORE_PLUGINS)
    try:
        sim.spawn_robot(parse_robot(CRATE, "model 'crate'"), "crate", Pose((3.0, 3.0, 0.15), (0.0, 0.0, 0.0, 1.0)))
        sim.step(100)
        resting = sim.engine.model_pose("crate").position
        try:
            with watchdog():
                sim.spawn_robot(parse_robot(urdf, "model 'fuzz'"), "fuzz")
        except BridgeError as error:
            assert "fuzz" not in sim.model_names(), "a refused model was left behind"
            refused(kind, error)
            return
        with watchdog():
            step_and_check(sim, kind)
            sim.step(steps)
            assert_finite_state(sim, kind)
            moved = math.dist(sim.engine.model_pose("crate").position, resting)
            assert moved < BYSTANDER_TOLERANCE, f"{kind}: the crate moved {moved * 1000:.3f} mm"
            sim.reset(simulation=False)
            sim.step(10)
            assert_finite_state(sim, f"{kind} after reset_world")
        tally(kind, "loaded")
    finally:
        sim.close()


def check_extreme_tag(hosts, case, text):
    host, index, tag, on_sensor = case
    urdf = with_tag(hosts[host], index, tag, on_sensor, text)
    try:
        spawn_beside_a_crate("extreme tag values", urdf)
    except AssertionError as error:
        raise AssertionError(f"{host}, plugin {index}, <{tag}> = {text}: {error}") from None


@settings(FUZZ, max_examples=draws(10, 20))
@given(data=st.data())
def test_extreme_finite_values_in_every_numeric_tag(data, tag_cases):
    hosts, cases = tag_cases
    check_extreme_tag(hosts, data.draw(st.sampled_from(cases)), data.draw(st.sampled_from(EXTREMES)))


@pytest.mark.skipif(not FULL_SWEEP, reason="the full sweep runs with MBOT_FULL_SWEEP=1")
def test_extreme_finite_values_in_every_numeric_tag_full_sweep(tag_cases):
    hosts, cases = tag_cases
    for case in cases:
        for text in EXTREMES:
            check_extreme_tag(hosts, case, text)


# -- link counts up to 1000 -----------------------------------------------------------------------------------------
LINK_COUNTS = (1, 2, 64, 127, 128, 129, 500, 1000)
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed")


def chain(links, joint_type):
    parts = ["<robot name='chain'><link name='l0'><inertial><mass value='1'/><inertia ixx='0.01' iyy='0.01' "
             "izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial><collision><geometry><box size='0.1 0.1 0.1'/>"
             "</geometry></collision></link>"]
    for index in range(1, links):
        parts.append(f"<link name='l{index}'><inertial><mass value='0.01'/><inertia ixx='1e-4' iyy='1e-4' "
                     f"izz='1e-4' ixy='0' ixz='0' iyz='0'/></inertial></link><joint name='j{index}' "
                     f"type='{joint_type}'><parent link='l{index - 1}'/><child link='l{index}'/>"
                     f"<origin xyz='0 0 0.001'/><axis xyz='0 0 1'/>"
                     f"<limit lower='-0.1' upper='0.1' effort='1' velocity='1'/></joint>")
    return "\n".join(parts) + "</robot>"


@settings(FUZZ, max_examples=draws(2, 4))
@given(links=st.sampled_from(LINK_COUNTS), joint_type=st.sampled_from(JOINT_TYPES))
def test_link_counts_up_to_1000(links, joint_type):
    spawn_beside_a_crate("link counts", chain(links, joint_type), steps=20)


@pytest.mark.skipif(not FULL_SWEEP, reason="the full sweep runs with MBOT_FULL_SWEEP=1")
def test_link_counts_up_to_1000_full_sweep():
    for links in LINK_COUNTS:
        for joint_type in JOINT_TYPES:
            spawn_beside_a_crate("link counts", chain(links, joint_type), steps=20)


# -- hostile structures: joint loops, deep nesting, many unknown elements, long chains ------------------------------
@st.composite
def hostile_structures(draw):
    """(kind, model XML, whether it is SDF): a random joint graph of up to six links (loops, joints to the world,
    links on two joints), elements nested up to 100,000 deep, up to 100,000 unknown elements, and SDF or one-line
    URDF chains around PyBullet's 128 links."""
    from test_hostile_models import links_and_joints, nested, sdf_chain, unknown_elements, urdf_chain
    kind = draw(st.sampled_from(("joint graph", "depth", "unknown elements", "sdf chain", "urdf chain")))
    if kind == "joint graph":
        links = [f"l{index}" for index in range(draw(st.integers(1, 6)))]
        ends = st.tuples(st.sampled_from(links + ["world"]), st.sampled_from(links))
        joints = draw(st.lists(ends, max_size=8, unique=True))
        return kind, links_and_joints(links, joints), True
    if kind == "depth":
        return kind, nested(draw(st.sampled_from((10, 98, 99, 100, 1000, 100000)))), True
    if kind == "unknown elements":
        return kind, unknown_elements(draw(st.sampled_from((1, 1000, 100000)))), True
    links = draw(st.integers(1, 130))
    return (kind, sdf_chain(links), True) if kind == "sdf chain" else (kind, urdf_chain(links), False)


@settings(FUZZ, max_examples=draws(15, 150))
@given(case=hostile_structures())
def test_hostile_structures_load_or_are_refused_in_one_line(case, simulation):
    kind, xml, sdf = case
    try:
        with watchdog():
            if sdf:
                simulation.add_world(read_spawned_model(xml, "hostile", Pose((0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0))))
            else:
                simulation.spawn_robot(parse_robot(xml, "model 'hostile'"), "hostile")
    except BridgeError as error:
        assert "hostile" not in simulation.model_names(), "a refused model was left behind"
        refused("hostile structures", error)
        return
    try:
        with watchdog():
            step_and_check(simulation, kind)
        tally("hostile structures", f"loaded ({kind})")
    finally:
        simulation.delete("hostile")


# -- gripper goals at and past the finger's limits ----------------------------------------------------------------
GRIPPER_GOALS = [(position, effort) for position in (0.0, 0.04, 0.04 + 1e-9, 0.05, -0.01, 5e-324, 1e308, -1e308)
                 for effort in (30.0, 0.0, 5e-324, 1e308)]


def test_gripper_goals_at_and_past_the_limits_all_end():
    """Each goal ends (succeeded, or aborted as stalled) within 3 s of sim time or is refused; the arm stays finite."""
    from ros_control_fixtures import run_until_ended
    from test_arm import arm

    from mbot_sim_bridge.core.ros_control.gripper_action_controller import GripperGoal
    sim, spawned, _, gripper = arm("effort")
    goals = GRIPPER_GOALS if FULL_SWEEP else GRIPPER_GOALS[::7]
    try:
        for position, effort in goals:
            if not gripper.accept_goal(GripperGoal(position, effort)):
                tally("gripper goals", "refused")
                continue
            end = run_until_ended(sim, gripper, seconds=3.0)
            tally("gripper goals", f"{end.status}{' stalled' if end.stalled else ''}")
            assert_finite_state(sim, f"gripper goal {position}, {effort}")
    finally:
        sim.close()
