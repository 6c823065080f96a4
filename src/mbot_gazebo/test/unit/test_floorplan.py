"""mbot_gazebo.floorplan and scripts/build_world: floor plans become worlds that load where the plan says."""
import logging
import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from mbot_gazebo.floorplan import FloorPlanError, load_floor_plan, main, merge_cells, world_sdf
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.world_bodies import load_world

PACKAGE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
REPO = os.path.abspath(os.path.join(PACKAGE, "..", ".."))
BUILD_WORLD = os.path.join(PACKAGE, "scripts", "build_world")
ROOM_PLAN = os.path.join(PACKAGE, "floorplans", "room.yaml")


def build_and_load(tmp_path, plan_text, client, caplog):
    """Plan text -> world file through main() -> PyBullet; the world must load without a warning."""
    plan = tmp_path / "plan.yaml"
    plan.write_text(plan_text)
    world = tmp_path / "plan.world"
    assert main([str(plan), "-o", str(world)]) == 0
    description = parse_world(str(world), model_path=[])
    loaded = load_world(client, description)
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []
    return description, loaded


def ray_hit(client, start, end):
    body, _, _, position, _ = client.rayTest(start, end)[0]
    return np.array(position) if body >= 0 else None


def run_build_world(*arguments):
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(PACKAGE, "src"),
                                                               os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, BUILD_WORLD, *arguments], capture_output=True, text=True,
                          env=environment, timeout=60)


def test_checked_in_room_world_is_the_output_of_its_floor_plan(tmp_path):
    output = tmp_path / "room.world"
    result = run_build_world(ROOM_PLAN, "-o", str(output))
    assert (result.returncode, result.stderr) == (0, "")
    with open(os.path.join(REPO, "worlds", "room.world")) as checked_in:
        assert output.read_text() == checked_in.read(), "rebuild worlds/room.world from floorplans/room.yaml"


def test_without_an_output_file_the_world_goes_to_standard_output():
    result = run_build_world(ROOM_PLAN)
    assert result.returncode == 0
    assert result.stdout == world_sdf(load_floor_plan(ROOM_PLAN), "room.yaml")


def test_walls_stand_where_the_plan_draws_them(tmp_path, client, caplog):
    description, loaded = build_and_load(tmp_path, """
world_name: plan_test
model_name: house
walls:
  - {start: [0, 0], end: [4, 0], thickness: 0.2, height: 1.5}
  - {start: [4, 0], end: [4, 3]}
""", client, caplog)
    assert description.name == "plan_test"
    (house,) = [model for model in description.models if model.name == "house"]
    assert house.static
    assert [(shape.link, shape.name) for shape in house.shapes] == [
        ("Wall_0", "Wall_0_Collision"), ("Wall_1", "Wall_1_Collision")]
    assert "ground_plane" in loaded.bodies
    # Wall_0: 0.2 thick about y = 0, 1.5 m tall; Wall_1 has the defaults, 0.15 m thick and 2.5 m tall.
    assert ray_hit(client, (2.0, -2.0, 0.5), (2.0, 2.0, 0.5)) == pytest.approx((2.0, -0.1, 0.5), abs=1e-5)
    assert ray_hit(client, (2.0, 0.0, 5.0), (2.0, 0.0, -1.0)) == pytest.approx((2.0, 0.0, 1.5), abs=1e-5)
    assert ray_hit(client, (6.0, 1.5, 0.5), (2.0, 1.5, 0.5)) == pytest.approx((4.075, 1.5, 0.5), abs=1e-5)
    assert ray_hit(client, (4.0, 1.5, 5.0), (4.0, 1.5, -1.0)) == pytest.approx((4.0, 1.5, 2.5), abs=1e-5)
    # Square ends close the outer corner: Wall_0 reaches 0.1 m past x = 4, so this ray meets it, not Wall_1.
    assert ray_hit(client, (4.05, -1.0, 0.5), (4.05, 1.0, 0.5)) == pytest.approx((4.05, -0.1, 0.5), abs=1e-5)


def test_merge_cells_covers_exactly_the_occupied_cells_with_few_rectangles():
    occupied = np.zeros((200, 200), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True  # a walled square
    occupied[50:60, 80:90] = True  # a pillar
    rectangles = merge_cells(occupied)
    assert len(rectangles) == 5
    covered = np.zeros_like(occupied, dtype=int)
    for row, column, rows, columns in rectangles:
        covered[row:row + rows, column:column + columns] += 1
    assert np.array_equal(covered, occupied.astype(int))  # every occupied cell once, nothing else


def _plan_with_image(image_name, extra=""):
    return f"""
wall_height: 0.5
occupancy:
  image: {image_name}
  resolution: 0.5
  origin: [1.0, 2.0, 0.0]
  occupied_thresh: 0.65
{extra}"""


def test_occupied_png_pixels_become_boxes_at_their_map_position(tmp_path, client, caplog):
    pixels = np.full((4, 6), 254, dtype=np.uint8)  # 6 wide, 4 tall: 3 m x 2 m from (1, 2)
    pixels[0, 4:6] = 0  # top row, two right pixels: x 3..4, y 3.5..4
    pixels[1:4, 0] = 10  # left column, lower three rows: x 1..1.5, y 2..3.5
    pixels[2, 2] = 120  # occupancy 0.53: below the threshold, free
    Image.fromarray(pixels).save(tmp_path / "map.png")
    description, _ = build_and_load(tmp_path, _plan_with_image("map.png"), client, caplog)
    boxes = sorted(shape.bounds() for shape in description.shapes if shape.kind == "box")
    assert len(boxes) == 2
    assert boxes[0][0] + boxes[0][1] == pytest.approx((1.0, 2.0, 0.0, 1.5, 3.5, 0.5))
    assert boxes[1][0] + boxes[1][1] == pytest.approx((3.0, 3.5, 0.0, 4.0, 4.0, 0.5))
    assert ray_hit(client, (3.5, 0.0, 0.25), (3.5, 10.0, 0.25)) == pytest.approx((3.5, 3.5, 0.25), abs=1e-5)


def test_binary_pgm_with_negate_and_a_turned_origin(tmp_path, client, caplog):
    pixels = np.zeros((2, 4), dtype=np.uint8)
    pixels[1, :] = 255  # negate: bright is occupied, so the bottom row: map x 0..2, y 0..0.5
    (tmp_path / "map.pgm").write_bytes(b"P5\n4 2\n255\n" + pixels.tobytes())
    plan = _plan_with_image("map.pgm", "  negate: 1\n  height: 1.0\n")
    plan = plan.replace("[1.0, 2.0, 0.0]", "[1.0, 2.0, 1.5707963267948966]")
    description, _ = build_and_load(tmp_path, plan, client, caplog)
    (box,) = [shape for shape in description.shapes if shape.kind == "box"]
    lower, upper = box.bounds()  # turned 90 degrees about (1, 2): map x runs along world y
    assert lower + upper == pytest.approx((0.5, 2.0, 0.0, 1.0, 4.0, 1.0), abs=1e-6)


def test_occupancy_can_name_a_map_server_map_yaml(tmp_path):
    maps = tmp_path / "maps"
    maps.mkdir()
    Image.fromarray(np.array([[0, 254]], dtype=np.uint8)).save(maps / "scan.png")
    (maps / "scan.yaml").write_text("image: scan.png\nresolution: 0.1\norigin: [-1.0, -1.0, 0.0]\n"
                                    "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    (tmp_path / "plan.yaml").write_text("occupancy: maps/scan.yaml\n")
    (block,) = load_floor_plan(str(tmp_path / "plan.yaml")).blocks
    assert block.centre == pytest.approx((-0.95, -0.95)) and (block.length, block.width) == pytest.approx((0.1, 0.1))


@pytest.mark.parametrize("plan_text, problem", [
    ("walls: [{start: [0, 0], end: [1, 0]}]\nwall_hieght: 2\n", "plan: unknown key 'wall_hieght'"),
    ("walls:\n  - {start: [0, 0], end: [1, 0]}\n  - {start: [0, 0]}\n", "walls[1]: missing 'end'"),
    ("walls:\n  - {start: [0, 0], end: [1, 'x']}\n", "walls[0].end: expected [x, y], got [1, 'x']"),
    ("walls:\n  - {start: [2, 2], end: [2, 2]}\n", "walls[0]: start and end are the same point [2.0, 2.0]"),
    ("walls:\n  - {start: [0, 0], end: [1, 0], thickness: -0.1}\n",
     "walls[0].thickness: expected a positive number, got -0.1"),
    ("walls: []\n", "nothing to build: no walls and no occupied cells"),
    ("occupancy: {image: nowhere.png, resolution: 0.05, origin: [0, 0, 0]}\n", "occupancy.image: cannot read"),
    ("- just\n- a list\n", "expected a mapping with 'walls' and/or 'occupancy'"),
    ("walls: [{start: [0, 0], end: [1, 0]}\n", "invalid YAML"),
])
def test_bad_plans_fail_with_one_line_naming_file_and_entry_and_exit_2(tmp_path, plan_text, problem):
    plan = tmp_path / "bad.yaml"
    plan.write_text(plan_text)
    output = tmp_path / "bad.world"
    result = run_build_world(str(plan), "-o", str(output))
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.startswith(f"build_world: error: {plan}") and result.stderr.count("\n") == 1
    assert problem in result.stderr
    assert not output.exists()


def test_a_missing_plan_fails_the_same_way(tmp_path):
    result = run_build_world(str(tmp_path / "nowhere.yaml"))
    assert result.returncode == 2
    assert result.stderr == f"build_world: error: {tmp_path / 'nowhere.yaml'}: cannot read: No such file or directory\n"


def test_load_floor_plan_raises_floor_plan_error(tmp_path):
    plan = tmp_path / "plan.yaml"
    plan.write_text("model_name: 'has spaces'\nwalls: [{start: [0, 0], end: [1, 0]}]\n")
    with pytest.raises(FloorPlanError, match="model_name: 'has spaces' must be letters, digits"):
        load_floor_plan(str(plan))
