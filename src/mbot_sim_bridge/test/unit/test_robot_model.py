import logging
import os
from xml.etree import ElementTree

import pytest

from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.description.robot_model import parse_robot

LINK = '<link name="{name}">{inertial}<collision><geometry>{geometry}</geometry></collision></link>'
INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'


def robot(*parts, name="probe"):
    return f"<robot name=\"{name}\">{''.join(parts)}</robot>"


def link(name, geometry='<box size="0.1 0.1 0.1"/>', inertial=INERTIAL):
    return LINK.format(name=name, geometry=geometry, inertial=inertial)


def joint(name, kind, parent, child, xyz="0 0 0"):
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>' if kind in ("revolute", "prismatic") else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><origin '
            f'xyz="{xyz}"/><axis xyz="0 1 0"/>{limit}</joint>')


def test_course_mbot_lumps_fixed_links_like_gazebo(mbot_urdf):
    model = parse_robot(mbot_urdf)
    assert model.name == "mbot" and model.root == "base_footprint"
    body, offset = model.lumped_into["base_link"]
    assert body == "base_footprint"
    assert offset.position == pytest.approx((0.0, 0.0, 0.005 / 2 + 0.01975 * 2))
    assert [j.name for j in model.movable_joints()] == ["back_caster_joint", "left_wheel_joint", "right_wheel_joint"]
    assert [p.get("filename") for p in model.plugins] == ["libgazebo_ros_diff_drive.so"]


def test_a_massless_root_takes_the_mass_lumped_into_it(mbot_urdf):
    model = parse_robot(mbot_urdf)
    assert not model.links["base_footprint"].has_inertial
    root = ElementTree.fromstring(model.pybullet_urdf).find("link[@name='base_footprint']")
    assert root.find("inertial/mass").get("value") == "20.0"
    assert float(root.find("inertial/origin").get("xyz").split()[2]) == pytest.approx(0.005 / 2 + 0.01975 * 2)
    assert not ElementTree.fromstring(model.pybullet_urdf).findall("link[@name='base_link']")
    assert "<gazebo" not in model.pybullet_urdf and "<transmission" not in model.pybullet_urdf


def test_caster_detection_is_by_shape_and_joint_not_by_name(mbot_urdf):
    assert parse_robot(mbot_urdf).caster_links({"left_wheel_joint", "right_wheel_joint"}) == ["back_caster_link"]
    urdf = robot(link("chassis"), link("front_ball", '<sphere radius="0.02"/>'),
                 link("wheel", '<cylinder radius="0.03" length="0.02"/>'),
                 joint("ball_mount", "fixed", "chassis", "front_ball"), joint("axle", "continuous", "chassis", "wheel"))
    assert parse_robot(urdf).caster_links({"axle"}) == ["front_ball"]


def test_explicit_friction_keeps_a_sphere_from_being_treated_as_a_caster():
    urdf = robot(link("chassis"), link("ball", '<sphere radius="0.02"/>'),
                 joint("mount", "continuous", "chassis", "ball"),
                 '<gazebo reference="ball"><mu1>0.3</mu1><mu2>0.3</mu2></gazebo>')
    assert parse_robot(urdf).caster_links(set()) == []


def test_massless_link_on_a_moving_joint_is_dropped_with_its_subtree(caplog):
    urdf = robot(link("chassis"), link("arm", inertial=""), link("hand"),
                 joint("shoulder", "revolute", "chassis", "arm"), joint("wrist", "fixed", "arm", "hand"))
    with caplog.at_level(logging.WARNING):
        model = parse_robot(urdf)
    assert set(model.links) == {"chassis"} and not model.joints
    assert any("link 'arm' has no <inertial> but moves on joint 'shoulder'" in r.getMessage() and "arm, hand"
               in r.getMessage() for r in caplog.records)


def test_sensor_blocks_are_collected_per_link():
    urdf = robot(link("chassis"), '<gazebo reference="chassis"><sensor type="ray" name="scanner"/></gazebo>')
    assert [(name, sensor.get("name")) for name, sensor in parse_robot(urdf).sensors()] == [("chassis", "scanner")]


def test_tags_without_effect_warn_once_naming_tag_and_model(caplog):
    urdf = robot(link("chassis"), '<gazebo reference="chassis"><kp>1e6</kp><turnGravityOff>true</turnGravityOff>'
                 '<selfCollide>false</selfCollide></gazebo>')
    with caplog.at_level(logging.WARNING):
        parse_robot(urdf, "model 'probe'")
        parse_robot(urdf, "model 'probe'")
    messages = [r.getMessage() for r in caplog.records]
    assert messages == ["model 'probe': <gazebo reference='chassis'> <kp> has no Bullet counterpart; ignored",
                        "model 'probe': <gazebo reference='chassis'> <turnGravityOff>true</turnGravityOff> is not "
                        "simulated; Gazebo's default applies"]


def test_unknown_gazebo_tags_warn_once_and_name_the_tag(caplog):
    urdf = robot(link("chassis"), '<gazebo reference="chassis"><sparkle>yes</sparkle></gazebo>',
                 '<gazebo><teleporter/></gazebo>', '<gazebo reference="nowhere"><mu1>1</mu1></gazebo>')
    with caplog.at_level(logging.WARNING):
        parse_robot(urdf)
    text = "\n".join(r.getMessage() for r in caplog.records)
    assert "<gazebo reference='chassis'> <sparkle> is not supported" in text
    assert "model-level <gazebo> tag <teleporter> is not supported" in text
    assert "<gazebo reference='nowhere'> names no link or joint" in text


def test_joint_blocks_warn_once_per_tag_except_provide_feedback(caplog):
    block = ('<gazebo reference="mount"><provideFeedback>true</provideFeedback><preserveFixedJoint>true'
             '</preserveFixedJoint><implicitSpringDamper>1</implicitSpringDamper><sparkle/></gazebo>')
    urdf = robot(link("chassis"), link("top"), joint("mount", "fixed", "chassis", "top"), block, block)
    with caplog.at_level(logging.WARNING):
        parse_robot(urdf, "model 'probe'")
        parse_robot(urdf, "model 'probe'")
    assert [r.getMessage() for r in caplog.records] == [
        "model 'probe': <gazebo reference='mount'> (a joint) <preserveFixedJoint> has no Bullet counterpart; ignored",
        "model 'probe': <gazebo reference='mount'> (a joint) <implicitSpringDamper> has no Bullet counterpart; ignored",
        "model 'probe': <gazebo reference='mount'> (a joint) <sparkle> is not supported on a joint; ignored"]


@pytest.mark.parametrize("xml, message", [
    ("", "robot_description is empty"),
    ("<robot name='a'><link name='x'>", "robot_description:1: not valid XML"),
    ("<sdf version='1.6'/>", "its root element is <sdf>, not <robot>"),
    ("<robot name='a'/>", "the robot has no <link>"),
    (robot(link("a"), joint("j", "continuous", "a", "b")), "joint 'j': child link 'b' is not defined"),
    (robot(link("a"), link("b"), joint("j", "universal", "a", "b")), "joint 'j': type 'universal' is not supported"),
    (robot(link("a"), link("b")), "expected one root link, found a, b"),
    (robot(link("a"), link("b"), joint("j", "fixed", "a", "b", xyz="0 zero 0")), "expected 3 numbers, got '0 zero 0'"),
])
def test_bad_urdf_gives_one_line_errors(xml, message):
    with pytest.raises(ModelError) as error:
        parse_robot(xml)
    assert message in str(error.value) and "\n" not in str(error.value)


def _mesh_robot(collision_mesh, visual_mesh):
    return robot('<link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
                 'ixz="0" iyz="0"/></inertial>'
                 f'<visual><geometry><mesh filename="{visual_mesh}"/></geometry></visual>'
                 f'<collision><geometry><mesh filename="{collision_mesh}"/></geometry></collision></link>')


def test_a_missing_collision_mesh_names_file_link_and_model(tmp_path):
    good = tmp_path / "good.stl"
    good.write_text("solid x\nendsolid x\n")
    with pytest.raises(ModelError) as error:
        parse_robot(_mesh_robot(tmp_path / "missing.stl", good), "model 'probe'")
    assert str(error.value) == (f"model 'probe': link 'base' collision mesh '{tmp_path}/missing.stl': "
                                f"No such file or directory")


def test_a_missing_visual_mesh_is_left_out_with_a_warning(tmp_path, caplog):
    good = tmp_path / "good.stl"
    good.write_text("solid x\nendsolid x\n")
    with caplog.at_level(logging.WARNING):
        model = parse_robot(_mesh_robot(good, f"file://{tmp_path}/gone.dae"), "model 'probe'")
    assert "gone.dae" not in model.pybullet_urdf and "good.stl" in model.pybullet_urdf
    assert (f"model 'probe': link 'base' visual mesh 'file://{tmp_path}/gone.dae': No such file or directory; "
            f"the visual is left out") in caplog.text


def test_a_mesh_that_is_not_a_regular_file_is_refused_unopened(tmp_path):
    fifo = tmp_path / "pipe.stl"
    os.mkfifo(fifo)
    with pytest.raises(ModelError, match="collision mesh '.*pipe.stl': not a regular file"):
        parse_robot(_mesh_robot(fifo, fifo), "model 'probe'")


def test_named_materials_stay_for_the_visuals_that_refer_to_them():
    urdf = robot('<material name="red"><color rgba="1 0 0 1"/></material>', link("a"))
    # PyBullet gets one element per line (robot_model.pybullet_text).
    text = parse_robot(urdf).pybullet_urdf.replace("\n", "")
    assert '<material name="red"><color rgba="1 0 0 1" /></material>' in text


@pytest.mark.parametrize("joints, message", [
    ('<joint name="shoulder" type="revolute"><parent link="chassis"/><child link="arm"/></joint>',
     r"^robot_description:\d+: joint 'shoulder' is of type revolute but it does not specify limits"),
    (joint("shoulder", "prismatic", "chassis", "arm").replace('lower="-1" upper="1"', 'lower="1" upper="-1"'),
     r"joint 'shoulder': <limit lower=\"1\"> is above upper=\"-1\"$"),
    (joint("a", "continuous", "chassis", "arm").replace("</joint>", '<mimic joint="a"/></joint>'),
     r"joint 'a': <mimic> joints follow each other in a circle: a -> a;"),
    (joint("a", "continuous", "chassis", "arm").replace("</joint>", '<mimic joint="b"/></joint>')
     + joint("b", "continuous", "arm", "hand").replace("</joint>", '<mimic joint="a"/></joint>'),
     r"joint 'a': <mimic> joints follow each other in a circle: a -> b -> a;"),
])
def test_joints_urdfdom_or_the_physics_cannot_take_are_refused_with_one_line(joints, message):
    links = "".join(f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" '
                    f'ixy="0" ixz="0" iyz="0"/></inertial></link>' for name in ("chassis", "arm", "hand"))
    with pytest.raises(ModelError, match=message):
        parse_robot(f'<robot name="r">{links}{joints}</robot>')
