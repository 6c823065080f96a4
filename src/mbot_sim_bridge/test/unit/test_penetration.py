"""Penetration undone as a Gazebo world asks (core/engine.py, Engine._bound_correction; the world's
<physics><ode><constraints>): robots spawned at z = 0 with their wheels 13 cm in the ground rise out instead of
being thrown, mesh and primitive bodies spawned half into the floor end on it, and bodies spawned into each other
separate without flying apart."""
import math
import os
import pathlib

import pytest
from ros_control_fixtures import WORKSPACE_SRC, load_yaml, simulate
from sensor_fixtures import expanded

from mbot_sim_bridge.core.errors import ModelError, WorldError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.package_uris import resolve_package_uris

HUSKY_SIZED_XACRO = os.path.join(WORKSPACE_SRC, "mobile_test_robots", "urdf", "husky_sized_base.urdf.xacro")
ROVER_XACRO = os.path.join(WORKSPACE_SRC, "rover_description", "urdf", "rover.urdf.xacro")
ROVER_CONTROL = os.path.join(WORKSPACE_SRC, "rover_control", "config", "control.yaml")
# An ASCII STL block, 1 x 0.5 x 0.25 m: PyBullet's URDF importer reads only binary STL.
ASCII_BLOCK = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "worlds", "meshes", "block.stl"))
# Both Husky-sized bases rest with base_link at the wheel radius minus the axles' offset above it.
HUSKY_REST_HEIGHT = 0.1651 - 0.03282
# SDF's <surface><contact><ode><max_vel>, which caps the correction's velocity below the world's default 100 m/s.
SURFACE_MAX_VEL = 0.01

WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="default">
  <physics type="ode"><max_step_size>0.001</max_step_size>{constraints}</physics>
  <include><uri>model://ground_plane</uri></include>
  {models}
</world></sdf>
"""
DYNAMIC_MODEL = """<model name="{name}"><pose>{x} {y} {z} 0 0 0</pose><static>{static}</static><link name="link">
    <inertial><mass>{mass}</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
    <collision name="collision"><geometry>{geometry}</geometry></collision></link></model>"""
BOX_ROBOT = """<robot name="{name}"><link name="block">
  <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.4" izz="0.5" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry>{geometry}</geometry></collision></link></robot>"""


def model(name, x=0.0, y=0.0, z=0.0, geometry="<box><size>1 1 1</size></box>", mass=1.0, static=False):
    return DYNAMIC_MODEL.format(name=name, x=x, y=y, z=z, geometry=geometry, mass=mass,
                                static=str(static).lower())


def world(tmp_path, *models, constraints=""):
    path = os.path.join(str(tmp_path), "penetration.world")
    with open(path, "w") as stream:
        stream.write(WORLD.format(constraints=constraints, models="\n  ".join(models)))
    return parse_world(path)


def husky_sized_base(sim, pose=IDENTITY):
    urdf = expanded(HUSKY_SIZED_XACRO)
    return sim.spawn_robot(parse_robot(urdf, "model 'husky'"), "husky", pose)


def record(sim, name, seconds, *others):
    """Per step, for the model ``name`` (and each of ``others``): its frame's position and the speed of its base
    as model_states reports it."""
    rows = {model_name: ([], []) for model_name in (name, *others)}
    for _ in range(round(seconds / sim.step_size)):
        sim.step(1)
        for model_name, (positions, speeds) in rows.items():
            positions.append(sim.engine.model_pose(model_name).position)
            speeds.append(math.hypot(*sim.engine.model_velocity(model_name)[0]))
    return rows[name] if not others else rows


def settled_at(heights, rest, step, tolerance=0.005):
    """Sim time from which every height is within ``tolerance`` of ``rest``."""
    outside = [index for index, height in enumerate(heights) if abs(height - rest) > tolerance]
    return (outside[-1] + 1 if outside else 0) * step


def check_rises_out_of_the_ground(sim, name, label):
    positions, speeds = record(sim, name, 1.5)
    heights = [position[2] for position in positions]
    settled = settled_at(heights, HUSKY_REST_HEIGHT, sim.step_size)
    print(f"figure: {label} spawned at z = 0 (wheels 13.2 cm in the ground): at {HUSKY_REST_HEIGHT:.4f} m from "
          f"{settled:.3f} s, highest {max(heights):.4f} m, fastest {max(speeds):.4f} m/s")
    assert settled <= 1.0
    assert max(heights) <= HUSKY_REST_HEIGHT + 0.03
    assert max(speeds) <= SURFACE_MAX_VEL * 1.05  # the cap at the wheels; the base pitches a little on the way
    return heights


def test_a_husky_sized_base_spawned_at_z_0_rises_onto_its_wheels_within_1_s_without_a_jump(tmp_path):
    sim = Simulation(world(tmp_path), CORE_PLUGINS)
    try:
        husky_sized_base(sim)
        check_rises_out_of_the_ground(sim, "husky", "Husky-sized base")
    finally:
        sim.close()


def test_the_rover_spawned_at_z_0_as_its_launch_file_does_rises_onto_its_wheels_within_1_s_without_a_jump():
    urdf = expanded(ROVER_XACRO, lidar_3d_enabled="false")
    sim, _, _ = simulate(urdf, load_yaml(ROVER_CONTROL), "rover", package_uris=resolve_package_uris,
                         namespace="/")
    try:
        check_rises_out_of_the_ground(sim, "rover", "rover")
    finally:
        sim.close()


def test_reset_world_puts_the_base_back_into_the_ground_and_it_rises_out_again(tmp_path):
    sim = Simulation(world(tmp_path), CORE_PLUGINS)
    try:
        husky_sized_base(sim)
        sim.step(300)
        sim.reset(simulation=False)
        assert sim.engine.model_pose("husky").position[2] == pytest.approx(0.0, abs=1e-9)
        check_rises_out_of_the_ground(sim, "husky", "Husky-sized base after reset_world")
    finally:
        sim.close()


@pytest.mark.parametrize("geometry", [f'<mesh filename="{ASCII_BLOCK}"/>', '<box size="1 0.5 0.25"/>'],
                         ids=["ascii_stl_mesh", "box"])
def test_a_robot_block_spawned_half_into_the_floor_ends_resting_on_it(tmp_path, geometry):
    sim = Simulation(world(tmp_path), CORE_PLUGINS)
    try:
        sim.spawn_robot(parse_robot(BOX_ROBOT.format(name="block", geometry=geometry), "model 'block'"), "block")
        positions, speeds = record(sim, "block", 1.5)
        heights = [position[2] for position in positions]
        print(f"figure: URDF block ({geometry.split()[0][1:]}) spawned half into the floor: ends at "
              f"{heights[-1]:.4f} m (0.125 on the floor), lowest {min(heights):.4f}, fastest {max(speeds):.4f} m/s")
        # Bullet keeps a convex mesh a 1 mm margin out.
        assert heights[-1] == pytest.approx(0.125, abs=0.0012)
        assert settled_at(heights, heights[-1], sim.step_size, tolerance=0.001) <= 0.2
        assert min(heights) >= 0.0
    finally:
        sim.close()


@pytest.mark.parametrize("text, problem", [
    ("solid x\n  facet normal 0 0 1\n", "mesh has no triangles"),
    (pathlib.Path(ASCII_BLOCK).read_text().replace("-0.5", "nan", 1), "non-finite"),
], ids=["no_triangles", "nan_vertex"])
def test_an_ascii_stl_pybullet_would_get_unreadable_refuses_the_spawn_naming_the_file(tmp_path, text, problem):
    path = tmp_path / "bad.stl"
    path.write_text(text)
    sim = Simulation(world(tmp_path), CORE_PLUGINS)
    try:
        with pytest.raises(ModelError, match=f"{path}: .*{problem}"):
            sim.spawn_robot(parse_robot(BOX_ROBOT.format(name="bad", geometry=f'<mesh filename="{path}"/>'),
                                        "model 'bad'"), "bad")
        assert sim.model_names() == ["ground_plane"]
    finally:
        sim.close()


@pytest.mark.parametrize("geometry", [f"<mesh><uri>{ASCII_BLOCK}</uri></mesh>", "<box><size>1 0.5 0.25</size></box>"],
                         ids=["mesh", "box"])
def test_an_sdf_block_spawned_half_into_the_floor_ends_resting_on_it(tmp_path, geometry):
    sim = Simulation(world(tmp_path, model("block", geometry=geometry)), CORE_PLUGINS)
    try:
        positions, speeds = record(sim, "block", 1.0)
        assert positions[-1][2] == pytest.approx(0.125, abs=0.0012)
        assert min(position[2] for position in positions) >= 0.0
        assert max(speeds) <= SURFACE_MAX_VEL * 1.001
    finally:
        sim.close()


def test_a_body_set_moving_on_the_ground_keeps_its_velocity(tmp_path):
    sim = Simulation(world(tmp_path, model("box", z=0.5)), CORE_PLUGINS)
    try:
        sim.step(100)
        sim.set_model_state("box", sim.engine.model_pose("box"), linear=(1.0, 0.0, 0.0))
        sim.step(1)
        # Friction takes about mu·g·dt = 0.01 m/s a step, and the box tips a little; only a penetration's
        # correction is capped (to 0.01 m/s).
        assert sim.engine.model_velocity("box")[0][0] > 0.98
    finally:
        sim.close()


def test_two_1_m_boxes_spawned_overlapping_by_0_3_m_separate_slowly(tmp_path):
    sim = Simulation(world(tmp_path, model("left", x=0.0, z=0.5), model("right", x=0.7, z=0.5)), CORE_PLUGINS)
    try:
        rows = record(sim, "left", 1.5, "right")
        (left, left_speeds), (right, right_speeds) = rows["left"], rows["right"]
        gap = right[-1][0] - left[-1][0]
        fastest = max(left_speeds + right_speeds)
        print(f"figure: two 1 m boxes spawned 0.3 m into each other: {gap:.4f} m apart after 1.5 s, fastest "
              f"{fastest:.4f} m/s, moved {-left[-1][0]:.3f} and {right[-1][0] - 0.7:.3f} m")
        assert gap == pytest.approx(1.0, abs=0.001)
        assert fastest < 1.0
        # Each is pushed about its share of the overlap, and neither slides on.
        assert 0.1 < -left[-1][0] < 0.2 and 0.1 < right[-1][0] - 0.7 < 0.2
    finally:
        sim.close()


def test_a_base_spawned_into_a_wall_comes_out_beside_it(tmp_path):
    # The chassis reaches x = 0.494; the wall's near face is at x = 0.3, so the base starts 0.19 m inside it, on
    # its wheels. (Spawned at z = 0 as well, with its wheels in the ground too, it comes out of both tipped onto
    # its nose against the wall: the wall's friction holds the front while the rear wheels rise.)
    wall = model("wall", x=0.4, z=0.5, geometry="<box><size>0.2 2 1</size></box>", static=True)
    sim = Simulation(world(tmp_path, wall), CORE_PLUGINS)
    try:
        husky_sized_base(sim, Pose((0.0, 0.0, HUSKY_REST_HEIGHT), IDENTITY.orientation))
        positions, speeds = record(sim, "husky", 1.0)
        front = positions[-1][0] + 0.9874 / 2
        print(f"figure: Husky-sized base spawned 0.19 m into a wall: its front ends {0.3 - front:.4f} m before the "
              f"wall, fastest {max(speeds):.4f} m/s, at height {positions[-1][2]:.4f} m")
        # Out, then rolling back on its free wheels at no more than the cap.
        assert 0.3 - SURFACE_MAX_VEL * 1.0 <= front <= 0.3 + 0.0001
        assert max(speeds) <= SURFACE_MAX_VEL * 1.05
        assert positions[-1][2] == pytest.approx(HUSKY_REST_HEIGHT, abs=0.005)
    finally:
        sim.close()


@pytest.mark.parametrize("constraints, cap", [
    ("", SURFACE_MAX_VEL),
    ("<ode><constraints><contact_max_correcting_vel>0.002</contact_max_correcting_vel></constraints></ode>", 0.002),
    ("<ode><constraints><contact_max_correcting_vel>100</contact_max_correcting_vel>"
     "<contact_surface_layer>0.001</contact_surface_layer></constraints></ode>", SURFACE_MAX_VEL),
], ids=["default", "world_cap_0.002", "gazebo_world_values"])
def test_the_correcting_velocity_is_the_smaller_of_the_worlds_and_the_surfaces(tmp_path, constraints, cap):
    sim = Simulation(world(tmp_path, model("block", geometry="<box><size>1 1 0.2</size></box>"),
                           constraints=constraints), CORE_PLUGINS)
    try:
        _, speeds = record(sim, "block", 0.3)
        # The cap holds where the block separates fastest, at a corner; its centre rises a little slower.
        assert 0.9 * cap <= max(speeds) <= cap * 1.001
    finally:
        sim.close()


def test_the_worlds_constraints_are_read_with_sdf_defaults(tmp_path):
    physics = world(tmp_path).physics
    assert (physics.erp, physics.contact_max_correcting_vel, physics.contact_surface_layer) == (0.2, 100.0, 0.001)
    physics = world(tmp_path, constraints="<ode><constraints><erp>0.5</erp><contact_max_correcting_vel>2"
                                          "</contact_max_correcting_vel><contact_surface_layer>0.002"
                                          "</contact_surface_layer></constraints></ode>").physics
    assert (physics.erp, physics.contact_max_correcting_vel, physics.contact_surface_layer) == (0.5, 2.0, 0.002)


@pytest.mark.parametrize("tag, value", [("erp", "nan"), ("erp", "1.5"), ("contact_max_correcting_vel", "inf"),
                                        ("contact_max_correcting_vel", "-1"), ("contact_surface_layer", "1e300"),
                                        ("contact_surface_layer", "x")])
def test_a_bad_constraint_is_refused_naming_it(tmp_path, tag, value):
    with pytest.raises(WorldError, match=f"<{tag}>"):
        world(tmp_path, constraints=f"<ode><constraints><{tag}>{value}</{tag}></constraints></ode>")


def test_a_cfm_says_once_that_it_is_not_applied(tmp_path, caplog):
    world(tmp_path, constraints="<ode><constraints><cfm>0.001</cfm></constraints></ode>")
    assert caplog.text.count("<cfm> is not applied") == 1


def test_a_box_wedged_between_two_walls_stays_slow_and_is_said_once(tmp_path, caplog):
    # A slab 0.8 m above the floor: the 1 m box cannot get out but by sliding 2 m sideways.
    slab = model("slab", z=0.9, geometry="<box><size>4 4 0.2</size></box>", static=True)
    sim = Simulation(world(tmp_path, slab, model("wedged", z=0.5)), CORE_PLUGINS)
    try:
        _, speeds = record(sim, "wedged", 1.01)
        assert max(speeds) <= SURFACE_MAX_VEL * 1.001
        assert caplog.text.count("model 'wedged' is still inside another model 1 s after it was placed") == 1
    finally:
        sim.close()
