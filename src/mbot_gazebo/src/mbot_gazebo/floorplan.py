"""Floor plan (YAML) -> SDF world: what Gazebo's Building Editor saves, written from data instead of drawn.

A plan lists wall segments and may add an occupancy image read the way map_server reads a map::

    world_name: default          # <world name>
    model_name: room             # the static model that holds every wall (default "building")
    wall_thickness: 0.15         # defaults for walls that do not set their own (the Building Editor's)
    wall_height: 2.5
    walls:
      - {start: [-2.6, -2.6], end: [4.6, -2.6]}
      - {start: [4.6, -2.6], end: [4.6, 2.6], thickness: 0.2, height: 1.0}
    occupancy:                   # optional; or the path of a map_server map .yaml
      image: furniture.pgm       # PNG or PGM, relative to the plan
      resolution: 0.05           # metres per pixel
      origin: [3.52, -2.525, 0]  # lower-left corner of the image: x, y, yaw
      occupied_thresh: 0.65
      negate: 0
      height: 0.75               # block height, default wall_height

Each wall becomes a box centred on its segment, extended by half its thickness at both ends so that walls
sharing an end point close the corner; a doorway between two walls is therefore the gap between their end
points minus one thickness. Occupied pixels are merged into rectangles, one box each. The world has the
sun, the ground plane, default physics and one static model with a link per box, named Wall_0, Wall_1, ...
as the Building Editor names them.
"""
import argparse
import math
import os
import re
import sys
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np
import yaml

DEFAULT_WALL_THICKNESS = 0.15
DEFAULT_WALL_HEIGHT = 2.5
_PLAN_KEYS = {"world_name", "model_name", "wall_thickness", "wall_height", "walls", "occupancy"}
_WALL_KEYS = {"start", "end", "thickness", "height"}
# map_server's keys (mode and free_thresh are accepted for compatibility: only occupied cells matter here)
_OCCUPANCY_KEYS = {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode", "height"}
_NAME = re.compile(r"^[A-Za-z0-9_.\-]+$")


class FloorPlanError(ValueError):
    """A plan that cannot be built; the message is one line naming the file and the entry."""


@dataclass(frozen=True)
class Block:
    """A static box standing on the floor: its centre (x, y), its length along ``yaw``, width across it, height."""
    centre: Tuple[float, float]
    yaw: float
    length: float
    width: float
    height: float


@dataclass(frozen=True)
class FloorPlan:
    world_name: str
    model_name: str
    blocks: Tuple[Block, ...]  # walls first, in plan order, then the occupancy rectangles


def wall_block(start: Sequence[float], end: Sequence[float], thickness: float, height: float) -> Block:
    """The box of a wall along start -> end (square ends, so corners close)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    return Block(((start[0] + end[0]) / 2.0, (start[1] + end[1]) / 2.0), math.atan2(dy, dx),
                 math.hypot(dx, dy) + thickness, thickness, height)


def merge_cells(occupied: np.ndarray) -> List[Tuple[int, int, int, int]]:
    """Cover the True cells of a 2-D grid with rectangles (row, column, rows, columns), sorted.

    Each row is cut into runs of consecutive cells, and a run continues the rectangle above it when it spans
    the same columns, so a wall drawn in a map becomes one box rather than one per pixel.
    """
    rectangles, open_runs = [], {}  # open_runs: (first column, end column) -> first row
    for row in range(occupied.shape[0] + 1):
        runs = set(_runs(occupied[row])) if row < occupied.shape[0] else set()
        for span, first_row in list(open_runs.items()):
            if span not in runs:
                rectangles.append((first_row, span[0], row - first_row, span[1] - span[0]))
                del open_runs[span]
        for span in runs:
            open_runs.setdefault(span, row)
    return sorted(rectangles)


def _runs(cells: np.ndarray) -> List[Tuple[int, int]]:
    edges = np.flatnonzero(np.diff(np.concatenate([[False], cells, [False]]).astype(np.int8)))
    return [(int(first), int(end)) for first, end in zip(edges[::2], edges[1::2])]


def occupancy_blocks(image: np.ndarray, resolution: float, origin: Sequence[float], occupied_thresh: float,
                     negate: bool, height: float) -> List[Block]:
    """Boxes for the occupied pixels of a grey image (row 0 at the top), with map_server's rules.

    Occupancy is (255 - p) / 255, or p / 255 with negate; a pixel is occupied above ``occupied_thresh``.
    ``origin`` is the world pose (x, y, yaw) of the lower-left corner of the image.
    """
    occupancy = image / 255.0 if negate else (255.0 - image) / 255.0
    occupied = occupancy > occupied_thresh
    x0, y0, yaw = origin
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    blocks = []
    for row, column, rows, columns in merge_cells(occupied):
        # Centre in the map frame, whose y grows upwards from the image's bottom row.
        u = (column + columns / 2.0) * resolution
        v = (occupied.shape[0] - row - rows / 2.0) * resolution
        centre = (x0 + cos_yaw * u - sin_yaw * v, y0 + sin_yaw * u + cos_yaw * v)
        blocks.append(Block(centre, yaw, columns * resolution, rows * resolution, height))
    return blocks


def load_floor_plan(path: str) -> FloorPlan:
    """Read and check a plan; raise FloorPlanError naming the file and the bad entry."""
    plan = _read_yaml(path)
    if not isinstance(plan, dict):
        raise FloorPlanError(f"{path}: expected a mapping with 'walls' and/or 'occupancy'")
    _check_keys(plan, _PLAN_KEYS, path, "plan")
    world_name = _name(plan, "world_name", "default", path)
    model_name = _name(plan, "model_name", "building", path)
    thickness = _positive(plan.get("wall_thickness", DEFAULT_WALL_THICKNESS), path, "wall_thickness")
    height = _positive(plan.get("wall_height", DEFAULT_WALL_HEIGHT), path, "wall_height")
    walls = plan.get("walls", [])
    if not isinstance(walls, list):
        raise FloorPlanError(f"{path}: walls: expected a list of {{start, end}} entries")
    blocks = [_wall(wall, thickness, height, path, f"walls[{index}]") for index, wall in enumerate(walls)]
    if plan.get("occupancy") is not None:
        blocks += _occupancy(plan["occupancy"], height, path)
    if not blocks:
        raise FloorPlanError(f"{path}: nothing to build: no walls and no occupied cells")
    return FloorPlan(world_name, model_name, tuple(blocks))


def world_sdf(plan: FloorPlan, source_name: str) -> str:
    """The SDF 1.6 world text for ``plan``; ``source_name`` is named in its header comment."""
    links = "".join(_wall_link(index, block) for index, block in enumerate(plan.blocks))
    return f"""<?xml version="1.0"?>
<sdf version="1.6">
  <!-- Built by build_world from {source_name}: edit the plan and build again rather than this file. -->
  <world name="{plan.world_name}">
    <include>
      <uri>model://sun</uri>
    </include>
    <include>
      <uri>model://ground_plane</uri>
    </include>
    <gravity>0 0 -9.8</gravity>
    <physics name="default_physics" default="true" type="ode">
      <max_step_size>0.001</max_step_size>
      <real_time_factor>1</real_time_factor>
      <real_time_update_rate>1000</real_time_update_rate>
    </physics>
    <model name="{plan.model_name}">
      <static>true</static>
      <pose>0 0 0 0 0 0</pose>
{links}    </model>
  </world>
</sdf>
"""


def _wall_link(index: int, block: Block) -> str:
    # Building Editor layout: the link sits on the floor at the wall's centre, the box is raised by half its height.
    name = f"Wall_{index}"
    size = f"{_number(block.length)} {_number(block.width)} {_number(block.height)}"
    raised = f"0 0 {_number(block.height / 2.0)} 0 0 0"
    geometry = f"""<geometry>
            <box>
              <size>{size}</size>
            </box>
          </geometry>"""
    return f"""      <link name="{name}">
        <pose>{_number(block.centre[0])} {_number(block.centre[1])} 0 0 0 {_number(block.yaw)}</pose>
        <collision name="{name}_Collision">
          <pose>{raised}</pose>
          {geometry}
        </collision>
        <visual name="{name}_Visual">
          <pose>{raised}</pose>
          {geometry}
          <material>
            <script>
              <uri>file://media/materials/scripts/gazebo.material</uri>
              <name>Gazebo/Grey</name>
            </script>
            <ambient>1 1 1 1</ambient>
          </material>
        </visual>
      </link>
"""


def _number(value: float) -> str:
    """Up to 6 decimals, no trailing zeros and no "-0", so the output is stable and diff-friendly."""
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def _read_yaml(path: str):
    try:
        with open(path, encoding="utf-8") as stream:
            return yaml.safe_load(stream)
    except OSError as error:
        raise FloorPlanError(f"{path}: cannot read: {error.strerror or error}") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark else path
        raise FloorPlanError(f"{where}: invalid YAML: {getattr(error, 'problem', None) or error}") from None


def _check_keys(entry: dict, known: set, path: str, label: str) -> None:
    unknown = sorted(set(map(str, entry)) - known)
    if unknown:
        raise FloorPlanError(f"{path}: {label}: unknown key '{unknown[0]}' (known: {', '.join(sorted(known))})")


def _name(plan: dict, key: str, default: str, path: str) -> str:
    value = str(plan.get(key, default))
    if not _NAME.match(value):
        raise FloorPlanError(f"{path}: {key}: '{value}' must be letters, digits, '_', '.' or '-'")
    return value


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _positive(value, path: str, label: str) -> float:
    if not _is_number(value) or value <= 0:
        raise FloorPlanError(f"{path}: {label}: expected a positive number, got {value!r}")
    return float(value)


def _numbers(value, lengths: Tuple[int, ...], path: str, label: str, shape: str) -> Tuple[float, ...]:
    if not isinstance(value, list) or len(value) not in lengths or not all(map(_is_number, value)):
        raise FloorPlanError(f"{path}: {label}: expected {shape}, got {value!r}")
    return tuple(float(v) for v in value)


def _wall(wall, thickness: float, height: float, path: str, label: str) -> Block:
    if not isinstance(wall, dict):
        raise FloorPlanError(f"{path}: {label}: expected a mapping with start and end, got {wall!r}")
    _check_keys(wall, _WALL_KEYS, path, label)
    for key in ("start", "end"):
        if key not in wall:
            raise FloorPlanError(f"{path}: {label}: missing '{key}'")
    start = _numbers(wall["start"], (2,), path, f"{label}.start", "[x, y]")
    end = _numbers(wall["end"], (2,), path, f"{label}.end", "[x, y]")
    if start == end:
        raise FloorPlanError(f"{path}: {label}: start and end are the same point {list(start)}")
    return wall_block(start, end, _positive(wall.get("thickness", thickness), path, f"{label}.thickness"),
                      _positive(wall.get("height", height), path, f"{label}.height"))


def _occupancy(entry, wall_height: float, path: str) -> List[Block]:
    label = "occupancy"
    base = os.path.dirname(os.path.abspath(path))
    if isinstance(entry, str):  # a map_server map: its image is relative to that yaml
        map_path = os.path.join(base, entry)
        entry, path, base = _read_yaml(map_path), map_path, os.path.dirname(map_path)
        label = "map"
    if not isinstance(entry, dict):
        raise FloorPlanError(f"{path}: {label}: expected a mapping like a map_server map yaml")
    _check_keys(entry, _OCCUPANCY_KEYS, path, label)
    for key in ("image", "resolution", "origin"):
        if key not in entry:
            raise FloorPlanError(f"{path}: {label}: missing '{key}'")
    resolution = _positive(entry["resolution"], path, f"{label}.resolution")
    origin = _numbers(entry["origin"], (2, 3), path, f"{label}.origin", "[x, y] or [x, y, yaw]")
    if len(origin) == 2:
        origin += (0.0,)
    threshold = entry.get("occupied_thresh", 0.65)
    if not _is_number(threshold) or not 0.0 <= threshold <= 1.0:
        raise FloorPlanError(f"{path}: {label}.occupied_thresh: expected a number in [0, 1], got {threshold!r}")
    negate = entry.get("negate", 0)
    if negate not in (0, 1):  # True and False compare equal to 1 and 0
        raise FloorPlanError(f"{path}: {label}.negate: expected 0 or 1, got {negate!r}")
    height = _positive(entry.get("height", wall_height), path, f"{label}.height")
    image = _grey_image(os.path.join(base, str(entry["image"])), path, f"{label}.image")
    return occupancy_blocks(image, resolution, origin, threshold, bool(negate), height)


def _grey_image(image_path: str, path: str, label: str) -> np.ndarray:
    """Pixel values 0-255 as floats; colour channels are averaged, as map_server does."""
    try:
        from PIL import Image, UnidentifiedImageError
    except ImportError:
        raise FloorPlanError(f"{path}: {label}: reading images needs Pillow (Debian: python3-pil)") from None
    try:
        with Image.open(image_path) as image:
            grey = image.mode in ("L", "1")
            pixels = np.asarray(image.convert("L" if grey else "RGB"), dtype=float)
    except (OSError, UnidentifiedImageError) as error:
        raise FloorPlanError(f"{path}: {label}: cannot read '{image_path}': {error}") from None
    return pixels.mean(axis=2) if pixels.ndim == 3 else pixels


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="build_world", description="Build an SDF world (walls as one static model) from a YAML floor plan.")
    parser.add_argument("plan", help="floor plan .yaml")
    parser.add_argument("-o", "--output", help="world file to write (default: standard output)")
    arguments = parser.parse_args(argv)
    try:
        text = world_sdf(load_floor_plan(arguments.plan), os.path.basename(arguments.plan))
    except FloorPlanError as error:
        print(f"build_world: error: {error}", file=sys.stderr)
        return 2
    if arguments.output is None:
        sys.stdout.write(text)
        return 0
    try:
        with open(arguments.output, "w", encoding="utf-8") as stream:
            stream.write(text)
    except OSError as error:
        print(f"build_world: error: {arguments.output}: cannot write: {error.strerror or error}", file=sys.stderr)
        return 2
    return 0
