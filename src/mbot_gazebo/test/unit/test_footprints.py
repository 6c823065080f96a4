"""Footprints: the top view of a world's collision shapes, as the demo picture and the soak run draw them."""
import math

import pytest
from mbot_sim_bridge.core.description.sdf_world import parse_world

from mbot_gazebo.footprints import footprint

WORLD = """<sdf version="1.6"><world name="footprints">
  <model name="ground"><static>true</static><link name="link"><collision name="plane">
    <geometry><plane><normal>0 0 1</normal><size>10 10</size></plane></geometry></collision></link></model>
  <model name="things"><static>true</static><pose>0 0 0 0 0 1.5707963267948966</pose><link name="link">
    <collision name="tip"><pose>1 0 0 0 0 0</pose><geometry><box><size>0.2 0.4 0.6</size></box></geometry></collision>
    <collision name="ball"><pose>2 -1 0.1 0 0 0</pose><geometry><sphere><radius>0.1</radius></sphere></geometry>
    </collision></link></model>
</world></sdf>"""


@pytest.fixture
def shapes(tmp_path):
    path = tmp_path / "footprints.world"
    path.write_text(WORLD)
    return {shape.name: shape for shape in parse_world(str(path), model_path=[]).shapes}


def test_a_box_turned_a_quarter_is_its_turned_rectangle(shapes):
    # 1 m along the model's x, which points along world y: centred at (0, 1), 0.4 wide in x, 0.2 deep in y.
    corners = sorted(footprint(shapes["tip"]))
    assert corners == pytest.approx([(-0.2, 0.9), (-0.2, 1.1), (0.2, 0.9), (0.2, 1.1)], abs=1e-6)


def test_a_sphere_is_a_32_gon_of_its_radius_counter_clockwise(shapes):
    polygon = footprint(shapes["ball"])  # model (2, -1) turned a quarter: world (1, 2)
    assert [math.hypot(x - 1.0, y - 2.0) for x, y in polygon] == pytest.approx([0.1] * 32, abs=1e-6)
    signed_area = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1]))
    assert signed_area > 0


def test_a_plane_has_no_footprint(shapes):
    assert footprint(shapes["plane"]) == ()
