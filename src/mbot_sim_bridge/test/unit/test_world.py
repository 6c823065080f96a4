"""core/world.py: .world files read as Gazebo 11 reads them, then built in PyBullet (DIRECT, no ROS master)."""
import glob
import logging
import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pybullet
import pytest

from mbot_sim_bridge.core.errors import WorldError
from mbot_sim_bridge.core.geometry import yaw
from mbot_sim_bridge.core.description.mesh import load_mesh
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.description.world_description import PhysicsConfig
from mbot_sim_bridge.core.world_bodies import load_world, world_lateral_friction
from mbot_sim_bridge.core.description.model_path import default_model_path

HERE = os.path.dirname(os.path.abspath(__file__))
TEST_WORLDS = os.path.join(HERE, "..", "worlds")
TEST_MODEL_PATH = [os.path.join(TEST_WORLDS, "models")]
REPO_WORLDS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "..", "worlds"))
SHIPPED_WORLDS = sorted(glob.glob(os.path.join(REPO_WORLDS, "*.world")))
GRAVITY = 9.8


@pytest.fixture
def no_gazebo_model_path(monkeypatch):
    """Shipped worlds must not depend on models a developer happens to have installed."""
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)


def read_test_world(name):
    return parse_world(os.path.join(TEST_WORLDS, name), model_path=TEST_MODEL_PATH)


def build(client, description):
    """What the Engine does with a world: its physics settings, then its bodies."""
    client.setGravity(*description.physics.gravity)
    client.setTimeStep(description.physics.max_step_size)
    return load_world(client, description)


def warnings_in(caplog):
    return [record.getMessage() for record in caplog.records if record.levelno >= logging.WARNING]


def shape_named(description, name, model=None):
    (shape,) = [shape for shape in description.shapes if shape.name == name and model in (None, shape.model)]
    return shape


def line_of(path, text):
    """1-based line of the first line of ``path`` that contains ``text``."""
    with open(path) as stream:
        return next(number for number, line in enumerate(stream, start=1) if text in line)


def step_until(client, condition, max_steps):
    for _ in range(max_steps):
        if condition():
            return True
        client.stepSimulation()
    return condition()


def ray_hit(client, start, end):
    """World point where the segment start -> end first hits something, or None."""
    body, _, _, position, _ = client.rayTest(start, end)[0]
    return np.array(position) if body >= 0 else None


def write(directory, name, text):
    path = directory / name
    path.write_text(text)
    return str(path)


def world_text(body, version="1.6"):
    return f'<?xml version="1.0"?>\n<sdf version="{version}">\n  <world name="w">\n{body}\n  </world>\n</sdf>\n'


BOX_MODEL = """    <model name="box">
      <static>true</static>
      <link name="link">
        <collision name="collision">
          <geometry><box><size>1 1 1</size></box></geometry>
        </collision>
      </link>
    </model>"""


# --- The shipped worlds --------------------------------------------------------------------------------------

@pytest.mark.parametrize("path", SHIPPED_WORLDS, ids=os.path.basename)
def test_shipped_world_loads_without_warnings(path, client, caplog, no_gazebo_model_path):
    description = parse_world(path)
    loaded = build(client, description)
    assert warnings_in(caplog) == []
    assert description.physics == PhysicsConfig()
    assert "ground_plane" in loaded.bodies
    assert len(loaded.shapes) == len(description.shapes)


def test_the_shipped_worlds_are_all_found():
    """Guards the parametrized test above, which would pass vacuously if the folder moved."""
    assert [os.path.basename(path) for path in SHIPPED_WORLDS] == ["empty.world", "playground.world", "room.world"]


def test_every_mesh_the_shipped_models_name_exists_and_reads():
    """Visuals included: Gazebo would load those too, though the bridge only collides."""
    models = os.path.join(REPO_WORLDS, "models")
    uris = [uri.text.strip() for path in glob.glob(os.path.join(models, "*", "model.sdf"))
            for uri in ET.parse(path).getroot().iter("uri") if uri.text.strip().startswith("model://")]
    assert len(uris) >= 6
    for uri in uris:
        assert len(load_mesh(os.path.join(models, uri[len("model://"):])).triangles) > 0, uri


@pytest.fixture
def playground(client, no_gazebo_model_path):
    description = parse_world(os.path.join(REPO_WORLDS, "playground.world"))
    return description, build(client, description)


def _distance_from_origin(shape):
    """Top-view distance from the origin to a convex shape that does not cover it: the nearest of the segments
    between any two of its points (its outline's edges among them; the others run inside it, farther away)."""
    points = shape.world_points()[:, :2]
    a, b = (array.reshape(-1, 2) for array in np.broadcast_arrays(points[:, None], points[None, :]))
    along = b - a
    t = np.clip(-np.einsum("ij,ij->i", a, along) / np.maximum(np.einsum("ij,ij->i", along, along), 1e-12), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + t[:, None] * along, axis=1)))


def test_playground_keeps_the_demo_rectangle_free(playground):
    description, _ = playground
    for shape in description.shapes:
        if shape.kind == "plane":
            continue
        (x_min, y_min, _), (x_max, y_max, _) = shape.bounds()
        assert x_max <= -1.5 or x_min >= 3.5 or y_max <= -1.5 or y_min >= 1.5, (shape.model, shape.name)


def test_playground_obstacles_lie_1_5_to_6_m_from_the_start(playground):
    description, _ = playground
    obstacles = [model for model in description.models if model.name != "ground_plane"]
    assert len(obstacles) >= 8
    for model in obstacles:
        nearest = min(_distance_from_origin(shape) for shape in model.shapes)
        assert 1.5 <= nearest <= 6.0, model.name


def test_a_6_m_lidar_at_the_start_sees_obstacles_all_around(playground, client):
    angles = np.radians(np.arange(0, 360))
    ends = np.stack([6.0 * np.cos(angles), 6.0 * np.sin(angles), np.full(360, 0.1)], axis=1)
    hits = client.rayTestBatch([(0.0, 0.0, 0.1)] * 360, ends.tolist())
    sectors_seen = {int(np.degrees(angle) // 45) for angle, hit in zip(angles, hits) if hit[0] >= 0}
    assert sectors_seen == set(range(8))


def test_playground_jersey_barrier_lies_across_the_x_axis_at_5_m(playground, client):
    description, _ = playground
    barrier = next(model for model in description.models if model.name == "jersey_barrier")
    assert barrier.static
    (_, y_min, z_min), (_, y_max, z_max) = barrier.shapes[0].bounds()
    assert z_min == pytest.approx(0.0, abs=1e-6) and z_max - z_min >= 0.3
    assert y_min <= -1.0 and y_max >= 1.0
    for y in (-1.0, 0.0, 1.0):
        hit = ray_hit(client, (0.0, y, 0.04), (6.0, y, 0.04))
        assert hit is not None and hit[0] == pytest.approx(5.0, abs=1e-4)


def test_playground_jersey_barrier_stops_a_robot_sized_disc_at_half_a_metre_per_second(playground, client):
    radius, height = 0.16, 0.045
    disc = client.createMultiBody(
        baseMass=20.0, baseCollisionShapeIndex=client.createCollisionShape(
            pybullet.GEOM_CYLINDER, radius=radius, height=height),
        basePosition=(4.0, 0.0, height / 2.0))
    client.changeDynamics(disc, -1, lateralFriction=0.0)  # rolls like the wheeled robot instead of scraping

    def front():
        return client.getBasePositionAndOrientation(disc)[0][0] + radius

    def drive_for(steps):
        for _ in range(steps):
            client.resetBaseVelocity(disc, (0.5, 0.0, 0.0), (0.0, 0.0, 0.0))
            client.stepSimulation()

    drive_for(3000)  # 1.7 s to reach the barrier, then 1.3 s pushing against it
    assert front() == pytest.approx(5.0, abs=0.01)
    assert client.getBasePositionAndOrientation(disc)[0][2] < height  # held back, not climbing the curb


# --- Poses ----------------------------------------------------------------------------------------------------

def test_nested_poses_compose_world_model_link_collision():
    description = read_test_world("nested_poses.world")
    assert [model.name for model in description.models] == ["outer"]
    assert [link.name for link in description.models[0].links] == ["base", "arm", "inner::link"]

    cylinder = shape_named(description, "lying_cylinder")
    assert cylinder.pose.position == pytest.approx((1.0, 1.0, 0.5), abs=1e-6)
    lower, upper = cylinder.bounds()  # pitched onto model x, which is world y
    assert lower == pytest.approx((0.9, 0.5, 0.4), abs=1e-3) and upper == pytest.approx((1.1, 1.5, 0.6), abs=1e-3)

    tip = shape_named(description, "tip")
    assert tip.pose.position == pytest.approx((0.0, 0.0, 1.0), abs=1e-6)
    assert abs(yaw(tip.pose.orientation)) == pytest.approx(math.pi, abs=1e-6)

    ball = shape_named(description, "ball")
    assert (ball.model, ball.link) == ("outer", "inner::link")
    assert ball.pose.position == pytest.approx((-1.0, 0.5, 0.1), abs=1e-6)


def test_sdf_1_7_relative_to_resolves_links_frames_and_the_model_frame(caplog):
    description = read_test_world("relative_to.world")
    assert shape_named(description, "box", "anchor").pose.position == pytest.approx((3.0, 1.0, 0.0), abs=1e-6)
    assert shape_named(description, "at_model_origin").pose.position == pytest.approx((2.0, 0.0, 0.0), abs=1e-6)
    assert shape_named(description, "on_link").pose.position == pytest.approx((3.0, 0.0, 1.0), abs=1e-6)
    placed = next(model for model in description.models if model.name == "placed")
    assert placed.pose.position == pytest.approx((1.0, 5.0, 0.0), abs=1e-6)
    assert warnings_in(caplog) == []


def test_unknown_relative_to_frame_warns_and_uses_the_model_frame(tmp_path, caplog):
    path = write(tmp_path, "frames.world", world_text("""    <model name="m">
      <pose>1 0 0 0 0 0</pose>
      <link name="link">
        <pose relative_to="nowhere">0 0 2 0 0 0</pose>
      </link>
    </model>""", version="1.7"))
    (model,) = parse_world(path, model_path=[]).models
    assert model.links[0].pose.position == pytest.approx((1.0, 0.0, 2.0))
    line = line_of(path, "nowhere")
    assert warnings_in(caplog) == [f"{path}:{line}: frame 'nowhere' does not exist in model 'm'; "
                                   f"using the model 'm' frame"]


# --- <include> and the model path ------------------------------------------------------------------------------

def test_include_picks_the_newest_supported_model_file_and_applies_name_pose_static(caplog):
    description = read_test_world("include.world")
    models = {model.name: model for model in description.models}
    assert list(models) == ["ground_plane", "versioned_box", "moved_box", "holder"]
    assert warnings_in(caplog) == []

    as_shipped = models["versioned_box"]
    assert as_shipped.static and as_shipped.pose.position == pytest.approx((0.0, 0.0, 0.25))
    assert as_shipped.shapes[0].size == (0.5, 0.5, 0.5)  # model.sdf (1.6), not the 1.4 or 1.8 file

    moved = models["moved_box"]
    assert not moved.static and moved.links[0].mass == 2.0
    assert moved.pose.position == pytest.approx((3.0, 4.0, 0.25))
    assert yaw(moved.pose.orientation) == pytest.approx(math.pi / 2)

    nested = models["holder"].shapes[0]
    assert nested.link == "nested_box::link"
    assert nested.pose.position == pytest.approx((1.0, -3.0, 0.25), abs=1e-6)


def test_ground_plane_and_sun_are_built_in_when_not_on_the_model_path():
    description = read_test_world("include.world")
    (plane,) = [shape for shape in description.shapes if shape.model == "ground_plane"]
    assert (plane.kind, plane.normal, plane.mu, plane.mu2) == ("plane", (0.0, 0.0, 1.0), 100.0, 50.0)
    assert description.models[0].static
    assert "sun" not in [model.name for model in description.models]  # a light, not a body


def test_model_path_wins_over_the_built_in_ground_plane(tmp_path):
    model = tmp_path / "models" / "ground_plane"
    model.mkdir(parents=True)
    write(model, "model.config", '<model><sdf version="1.6">model.sdf</sdf></model>')
    write(model, "model.sdf", '<sdf version="1.6"><model name="ground_plane"><static>1</static><link name="l">'
                              '<collision name="c"><geometry><box><size>9 9 1</size></box></geometry></collision>'
                              '</link></model></sdf>')
    path = write(tmp_path, "w.world", world_text("<include><uri>model://ground_plane</uri></include>"))
    assert parse_world(path, model_path=[str(tmp_path / "models")]).shapes[0].kind == "box"


def test_unknown_model_uri_warns_once_naming_it_and_the_search_path_and_the_rest_loads(tmp_path, caplog, client):
    path = write(tmp_path, "w.world", world_text("    <include><uri>model://no_such_model</uri></include>\n"
                                                 + BOX_MODEL))
    for _ in range(2):
        description = parse_world(path, model_path=["/nonexistent/models", str(tmp_path)])
    assert [model.name for model in description.models] == ["box"]
    assert "box" in build(client, description).bodies
    assert warnings_in(caplog) == [f"{path}:4: cannot find 'model://no_such_model' "
                                   f"(model path: /nonexistent/models:{tmp_path}); skipped"]


def test_default_model_path_is_gazebo_model_path_then_the_workspace_models(monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", "/opt/models::/home/me/models")
    assert default_model_path() == ["/opt/models", "/home/me/models", os.path.join(REPO_WORLDS, "models")]
    monkeypatch.delenv("GAZEBO_MODEL_PATH")
    assert default_model_path() == [os.path.join(REPO_WORLDS, "models")]


# --- Physics and friction ----------------------------------------------------------------------------------------

def test_physics_sdf_1_6_reads_gravity_from_the_world():
    assert read_test_world("physics_1_6.world").physics == PhysicsConfig(0.002, 0.0, 0.0, (0.5, 0.0, -3.71))


def test_physics_sdf_1_5_reads_gravity_from_the_default_physics_profile():
    assert read_test_world("physics_1_5.world").physics == PhysicsConfig(0.004, 2.5, 250.0, (0.0, 0.0, -1.62))


def test_physics_defaults_without_a_physics_element(tmp_path):
    path = write(tmp_path, "w.world", world_text(BOX_MODEL))
    description = parse_world(path, model_path=[])
    assert description.physics == PhysicsConfig(0.001, 1.0, 1000.0, (0.0, 0.0, -9.8))
    assert (description.name, description.path) == ("w", path)


@pytest.mark.parametrize("mu, mu2, expected", [(100.0, 50.0, 1.0), (1.0, 1.0, 1.0), (0.5, 0.8, 0.5),
                                               (0.9, 0.2, 0.2)])
def test_world_lateral_friction_is_the_smallest_of_mu_mu2_and_1(mu, mu2, expected):
    assert world_lateral_friction(mu, mu2) == expected


def test_loaded_collisions_get_the_friction_rule_and_no_bounce(client):
    loaded = build(client, read_test_world("include.world"))
    # A static model of one collision is a single object: its only link is -1.
    ground = client.getDynamicsInfo(loaded.bodies["ground_plane"], -1)
    box = client.getDynamicsInfo(loaded.bodies["versioned_box"], -1)
    assert (ground[1], ground[5]) == (1.0, 0.0)  # lateral friction, restitution
    assert box[1] == pytest.approx(0.3)


def test_a_block_with_mu_1_slides_on_mu_0_5_as_far_as_ode_lets_it(client):
    """ODE pairs mu 1 with the rink's min(0.5, 0.8): the block stops after v² / (2 μ g)."""
    build(client, read_test_world("friction.world"))
    block = client.createMultiBody(1.0, client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(0.1,) * 3),
                                   basePosition=(-3.0, 0.0, 0.1))
    client.changeDynamics(block, -1, lateralFriction=1.0)
    client.resetBaseVelocity(block, (2.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert step_until(client, lambda: np.linalg.norm(client.getBaseVelocity(block)[0]) < 1e-3, max_steps=5000)
    travelled = client.getBasePositionAndOrientation(block)[0][0] + 3.0
    assert travelled == pytest.approx(2.0 ** 2 / (2 * 0.5 * GRAVITY), rel=0.05)


# --- Bodies --------------------------------------------------------------------------------------------------

def test_ray_hits_a_loaded_box_where_the_sdf_puts_it(client):
    loaded = build(client, read_test_world("include.world"))
    body, link, _, position, _ = client.rayTest((3.0, 0.0, 0.25), (3.0, 10.0, 0.25))[0]
    assert body == loaded.bodies["moved_box"] and link == 0
    assert position == pytest.approx((3.0, 3.75, 0.25), abs=1e-5)
    assert ray_hit(client, (1.0, -3.0, 2.0), (1.0, -3.0, -1.0)) == pytest.approx((1.0, -3.0, 0.5), abs=1e-5)


def test_a_dynamic_model_falls_and_a_static_one_stays(client):
    loaded = build(client, read_test_world("dynamics.world"))
    falling, fixed = loaded.bodies["falling"], loaded.bodies["fixed"]
    mass, _, inertia = client.getDynamicsInfo(falling, -1)[:3]
    assert mass == 2.0 and inertia == pytest.approx((0.01, 0.02, 0.03))
    assert client.getDynamicsInfo(fixed, -1)[0] == 0.0

    def height():
        return loaded.model_pose(client, "falling").position[2]

    assert step_until(client, lambda: height() < 0.5, max_steps=1000)
    # Lands flat: its centre of mass is 0.1 m off centre but over the footprint; half its height up.
    assert step_until(client, lambda: abs(height() - 0.1) < 1e-4
                      and np.linalg.norm(client.getBaseVelocity(falling)[0]) < 1e-4, max_steps=3000)
    assert loaded.model_pose(client, "falling").position[:2] == pytest.approx((0.0, 0.0), abs=0.01)
    assert loaded.model_pose(client, "fixed").position == pytest.approx((2.0, 0.0, 1.0), abs=1e-9)


def test_meshes_of_every_format_and_kind_of_uri(client, caplog):
    description = read_test_world("meshes.world")
    assert shape_named(description, "stl_block").size == pytest.approx((2.0, 1.0, 0.5))
    assert shape_named(description, "obj_pyramid").size == pytest.approx((1.0, 1.0, 1.0))
    wedge = shape_named(description, "dae_wedge")
    assert wedge.size == pytest.approx((1.0, 1.0, 2.0))  # COLLADA unit 0.1 m, times the SDF scale
    lower, upper = wedge.bounds()
    assert lower + upper == pytest.approx((-4.5, 0.0, 0.0, -3.5, 1.0, 2.0))
    assert wedge.mesh_path.endswith(os.path.join("models", "wedge", "meshes", "wedge.dae"))

    loaded = build(client, description)
    assert len(loaded.shapes) == 4 and warnings_in(caplog) == []
    assert ray_hit(client, (5.0, 0.0, 3.0), (5.0, 0.0, -1.0)) == pytest.approx((5.0, 0.0, 1.0), abs=1e-4)
    assert ray_hit(client, (0.0, 0.0, 3.0), (0.0, 0.0, -1.0)) == pytest.approx((0.0, 0.0, 0.5), abs=1e-4)


def test_binary_stl_reads_like_ascii_stl(tmp_path):
    ascii_mesh = load_mesh(os.path.join(TEST_WORLDS, "meshes", "block.stl"))
    corners = ascii_mesh.vertices[ascii_mesh.triangles].astype("<f4")
    stl_triangle = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
    records = np.zeros(len(corners), dtype=stl_triangle)
    records["vertices"] = corners
    path = tmp_path / "block.stl"
    path.write_bytes(b"solid but binary".ljust(80, b" ") + np.uint32(len(records)).tobytes() + records.tobytes())
    binary_mesh = load_mesh(str(path))
    assert np.array_equal(binary_mesh.vertices, ascii_mesh.vertices)
    assert np.array_equal(binary_mesh.triangles, ascii_mesh.triangles)


# --- Bad input ---------------------------------------------------------------------------------------------------

def test_missing_world_file_is_a_world_error_naming_it(tmp_path):
    path = str(tmp_path / "nowhere.world")
    with pytest.raises(WorldError, match=f"^{path}: cannot read: No such file or directory$"):
        parse_world(path)


def test_malformed_xml_is_a_world_error_with_file_and_line(tmp_path):
    path = write(tmp_path, "play.world", world_text("    <model name='m'>\n      <link name='l'>\n    </model>"))
    with pytest.raises(WorldError) as error:
        parse_world(path)
    assert str(error.value) == f"{path}:6: not valid XML: mismatched tag"


def test_a_file_without_a_world_is_a_world_error(tmp_path):
    path = write(tmp_path, "robot.urdf", "<robot name='r'/>")
    with pytest.raises(WorldError, match="not an SDF world"):
        parse_world(path)


@pytest.mark.parametrize("bad, message", [
    ("<box><size>1 1</size></box>", "<size>: expected 3 numbers, got '1 1'"),
    ("<sphere><radius>-1</radius></sphere>", "<radius>: -1 is outside the valid range > 0 and <= 100000"),
    ("<sphere><radius>nan</radius></sphere>", "<radius>: NaN is not a valid value: 'nan'"),
    ("<box><size>1 inf 1</size></box>", "<size>: infinity is not a valid value: '1 inf 1'"),
])
def test_bad_values_are_world_errors_with_file_and_line(tmp_path, bad, message):
    path = write(tmp_path, "w.world", world_text(f"""    <model name="m">
      <static>true</static>
      <link name="l">
        <collision name="c">
          <geometry>{bad}</geometry>
        </collision>
      </link>
    </model>"""))
    with pytest.raises(WorldError) as error:
        parse_world(path)
    assert str(error.value) == f"{path}:{line_of(path, bad)}: {message}"


def test_an_unreadable_mesh_warns_and_only_its_collision_is_skipped(tmp_path, caplog, client):
    (tmp_path / "broken.stl").write_text("this is not a mesh")
    path = write(tmp_path, "w.world", world_text("""    <model name="m">
      <static>true</static>
      <link name="l">
        <collision name="broken">
          <geometry><mesh><uri>broken.stl</uri></mesh></geometry>
        </collision>
        <collision name="missing">
          <geometry><mesh><uri>missing.obj</uri></mesh></geometry>
        </collision>
        <collision name="fine">
          <geometry><box><size>1 1 1</size></box></geometry>
        </collision>
      </link>
    </model>"""))
    description = parse_world(path, model_path=[])
    assert [shape.name for shape in build(client, description).shapes] == ["fine"]
    assert warnings_in(caplog) == [
        f"{tmp_path}/broken.stl: mesh has no triangles; collisions using it are skipped",
        f"{path}:{line_of(path, 'missing.obj')}: cannot find mesh 'missing.obj'; collision 'missing' of model 'm' "
        f"skipped"]


def test_what_is_not_simulated_warns_once_each_and_the_rest_loads(caplog, client):
    for _ in range(2):
        description = read_test_world("unsupported.world")
    path = os.path.join(TEST_WORLDS, "unsupported.world")

    def at(text):
        return f"{path}:{line_of(path, text)}: "

    # The world's <plugin>s are the Simulation's to build or report (test_link_attacher.py): the reading is silent.
    assert sorted(warnings_in(caplog)) == sorted([
        at("<actor") + "<actor name='walker'> is not simulated; ignored",
        at("<teleporter") + "<teleporter> is not an SDF <world> element; ignored, here and wherever else this file "
                            "has it",
        at("<polyline>") + "<polyline> is not supported; collision 'post' of model 'door' skipped",
        at("<gravity>") + "<gravity>false</gravity> in link 'panel' of model 'door' is not simulated",
        at("<gripper") + "<gripper name='grip'> is not simulated; ignored",
    ])
    assert [shape.name for shape in build(client, description).shapes] == ["box", "panel"]


def test_a_second_model_with_the_same_name_warns_and_is_skipped(tmp_path, caplog):
    path = write(tmp_path, "w.world", world_text(BOX_MODEL + "\n" + BOX_MODEL.replace("1 1 1", "2 2 2")))
    (model,) = parse_world(path, model_path=[]).models
    assert model.shapes[0].size == (1.0, 1.0, 1.0)
    assert warnings_in(caplog) == [f"{path}:12: a model named 'box' already exists; this one is skipped"]


def test_a_model_that_includes_itself_is_a_world_error(tmp_path):
    model = tmp_path / "models" / "loop"
    model.mkdir(parents=True)
    write(model, "model.config", '<model><sdf version="1.6">model.sdf</sdf></model>')
    write(model, "model.sdf", '<sdf version="1.6"><model name="loop"><include><uri>model://loop</uri></include>'
                              '</model></sdf>')
    path = write(tmp_path, "w.world", world_text("<include><uri>model://loop</uri></include>"))
    with pytest.raises(WorldError) as error:
        parse_world(path, model_path=[str(tmp_path / "models")])
    assert str(error.value) == f"{model}/model.sdf:1: {model}/model.sdf includes itself"
