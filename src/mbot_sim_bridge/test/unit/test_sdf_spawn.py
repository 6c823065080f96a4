import pytest

from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world

BOX = """<sdf version="1.6"><model name="crate"><static>true</static><pose>1 0 0.25 0 0 0</pose>
  <link name="link"><collision name="c"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision>
  </link></model></sdf>"""


def parse(tmp_path, xml):
    path = tmp_path / "spawn.world"
    path.write_text(xml)
    return parse_world(str(path))


def test_model_is_renamed_and_placed_at_the_spawn_pose_composed_with_its_own(tmp_path):
    xml = spawn_world_xml(BOX, "box_a", pose_from_xyz_rpy((2.0, 3.0, 0.0), (0.0, 0.0, 1.5707963267948966)))
    world = parse(tmp_path, xml)
    assert [model.name for model in world.models] == ["box_a"]
    assert world.shapes[0].pose.position == pytest.approx((2.0, 4.0, 0.25), abs=1e-6)


def test_database_include_gets_the_name_and_pose(tmp_path):
    xml = spawn_world_xml("<sdf version='1.6'><world name='default'><include><uri>model://ground_plane</uri>"
                          "</include></world></sdf>", "floor", pose_from_xyz_rpy((0, 0, 1.0), (0, 0, 0)))
    assert [model.name for model in parse(tmp_path, xml).models] == ["floor"]


@pytest.mark.parametrize("xml, message", [
    ("<robot name='r'/>", "is not SDF: its root element is <robot>"),
    ("<sdf version='1.6'>", "not valid XML"),
    ("<sdf version='1.6'/>", "expected exactly one <model>"),
    ("<sdf version='1.6'><model name='m'><pose>1 2</pose></model></sdf>",
     "<pose> .x y z roll pitch yaw.: expected 6 numbers, got '1 2'"),
])
def test_bad_sdf_models_are_refused_with_one_line(xml, message):
    with pytest.raises(ModelError, match=message):
        spawn_world_xml(xml, "probe", pose_from_xyz_rpy((0, 0, 0), (0, 0, 0)))
