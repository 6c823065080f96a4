"""SDF models with joints, sensors and plugins: read as the URDF robots are (core/description/sdf_model.py) and
simulated by the same path, from world files, includes and spawn_sdf_model."""
import math
import os

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.description.world_writer import take_snapshot, world_sdf, write_world_file
from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.errors import BridgeError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose, compose, inverse, pose_from_xyz_rpy, rotation_matrix
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.sensors.lidar import RaySensor
from mbot_sim_bridge.core.sensors.p3d import P3D
from mbot_sim_bridge.core.simulation import Simulation
from sensor_fixtures import measured_motion, plugin_of, world_simulation

HERE = os.path.dirname(os.path.abspath(__file__))
TEST_WORLDS = os.path.join(HERE, "..", "worlds")
TEST_MODEL_PATH = [os.path.join(TEST_WORLDS, "models")]

# The pendulum of double_pendulum.world: two uniform rods of mass m and length l, each hinged at its top end,
# the lower one at the upper one's bottom end; centre of mass a = l/2 below each hinge, moment about it m l²/12.
G, MASS, LENGTH = 9.8, 1.0, 0.5
CENTRE, MOMENT = LENGTH / 2.0, 0.0208333


def normal_mode_periods():
    """Small-angle periods and mode shapes of the double pendulum, from its Lagrangian.

    With θ1, θ2 the rods' angles from the vertical, for small angles T = ½ θ̇ᵀ M θ̇ and V = ½ θᵀ K θ with
    M = [[m a² + I + m l², m l a], [m l a, m a² + I]] (the lower rod's centre moves with l θ1 + a θ2) and
    K = g diag(m a + m l, m a). The normal modes solve K v = ω² M v; each period is 2π/ω.
    Returns (period, (θ1, θ2) shape) for the slow and the fast mode.
    """
    inertia = np.array([[MASS * CENTRE ** 2 + MOMENT + MASS * LENGTH ** 2, MASS * LENGTH * CENTRE],
                        [MASS * LENGTH * CENTRE, MASS * CENTRE ** 2 + MOMENT]])
    stiffness = G * np.diag([MASS * CENTRE + MASS * LENGTH, MASS * CENTRE])
    squared, shapes = np.linalg.eig(np.linalg.solve(inertia, stiffness))
    order = np.argsort(squared)
    return [(2.0 * math.pi / math.sqrt(squared[k]), shapes[:, k] / shapes[0, k]) for k in order]


@pytest.fixture(scope="module")
def pendulum():
    simulation = Simulation(parse_world(os.path.join(TEST_WORLDS, "double_pendulum.world")), CORE_PLUGINS)
    yield simulation
    simulation.close()


def upward_crossings(times, values):
    return [t0 - v0 * (t1 - t0) / (v1 - v0)
            for t0, t1, v0, v1 in zip(times, times[1:], values, values[1:]) if v0 < 0.0 <= v1]


@pytest.mark.parametrize("mode", [0, 1], ids=["slow mode", "fast mode"])
def test_an_sdf_double_pendulum_swings_with_the_periods_of_its_normal_modes(pendulum, mode):
    """Started in one normal mode (0.02 rad on the shoulder; the elbow's angle is the rods' difference), the
    shoulder swings at that mode's period within 2 %."""
    period, shape = normal_mode_periods()[mode]
    pendulum.reset(simulation=True)
    upper, lower = 0.02 * shape
    pendulum.set_model_configuration("double_pendulum", ["shoulder", "elbow"], [upper, lower - upper])
    robot = pendulum.models["double_pendulum"].robot
    times, angles = [], []
    for _ in range(int(2.5 * period / pendulum.step_size)):
        pendulum.step(1)
        times.append(pendulum.sim_time)
        angles.append(robot.joint_state(["shoulder"])[0][0])
    crossings = upward_crossings(times, angles)
    assert len(crossings) >= 2
    measured = float(np.mean(np.diff(crossings)))
    assert measured == pytest.approx(period, rel=0.02), f"measured {measured:.4f} s, predicted {period:.4f} s"
    assert max(np.abs(angles)) == pytest.approx(0.02, rel=0.1)  # one mode only: the amplitude stays


def test_the_pendulum_is_a_robot_with_its_joints_and_a_joint_state_publisher(pendulum):
    spawned = pendulum.models["double_pendulum"]
    assert spawned.robot.movable_joints == ["shoulder", "elbow"]
    assert spawned.robot.model.anchored  # its shoulder joint's parent is the world
    assert [type(plugin).__name__ for plugin in spawned.plugins] == ["JointStatePublisher"]
    assert "double_pendulum" not in pendulum.world_models


def spawned_sdf(simulation, tmp_path, model_xml, name, pose=(0.0, 0.0, 0.0), namespace=""):
    """What spawn_sdf_model does: the request's XML wrapped in a world, read and added."""
    path = tmp_path / f"spawn_{name}.world"
    path.write_text(spawn_world_xml(model_xml, name, pose_from_xyz_rpy(pose, (0.0, 0.0, 0.0)), namespace))
    return simulation.add_world(parse_world(str(path), TEST_MODEL_PATH), namespace or "/")


@pytest.fixture(scope="module")
def flat_world(tmp_path_factory):
    simulation = world_simulation(tmp_path_factory.mktemp("sdf_models"))
    yield simulation
    simulation.close()


BURGER = "<sdf version='1.6'><world name='default'><include><uri>model://sdf_burger</uri></include></world></sdf>"


@pytest.mark.parametrize("linear, angular", [(0.2, 0.0), (0.15, 0.5)])
def test_a_turtlebot3_style_model_sdf_drives_as_cmd_vel_says(flat_world, tmp_path, linear, angular):
    """sdf_burger (test/worlds/models) is written as TurtleBot3's model.sdf: links at the model origin, joints posed
    in their child links with the wheel axis in the joint frame, libgazebo_ros_diff_drive.so beside the links.
    Spawned as spawn_model -database spawns it, it drives within 5 % of the command."""
    name = f"burger_{len(flat_world.model_names())}"
    spawned_sdf(flat_world, tmp_path, BURGER, name, pose=(0.0, 3.0 * len(flat_world.model_names()), 0.01))
    spawned = flat_world.models[name]
    drive = plugin_of(spawned, DiffDrive)
    assert spawned.robot.movable_joints == ["wheel_left_joint", "wheel_right_joint"]
    speed, rate = measured_motion(flat_world, spawned, lambda: drive.set_command(linear, angular))
    print(f"figure: sdf_burger at ({linear}, {angular}): {speed:.4f} m/s, {rate:.4f} rad/s")
    assert speed == pytest.approx(linear, rel=0.05)
    assert rate == pytest.approx(angular, abs=0.05 * max(abs(angular), abs(linear) / 0.08))
    # base_link is lumped into base_footprint at its fixed joint, 1 cm up; its SDF frame is the model origin too.
    base_link, base_footprint = (spawned.robot.link_world_pose(link) for link in ("base_link", "base_footprint"))
    assert base_link.position == pytest.approx(base_footprint.position, abs=1e-6)


def test_spawn_sdf_model_puts_the_robot_namespace_in_every_plugin(flat_world, tmp_path):
    """As spawn_model -sdf -file model.sdf -robot_namespace sends it (an <include> has no plugins to put it in, in
    gazebo_ros too)."""
    with open(os.path.join(TEST_MODEL_PATH[0], "sdf_burger", "model.sdf")) as model_file:
        spawned_sdf(flat_world, tmp_path, model_file.read(), "tb3_0", pose=(5.0, -5.0, 0.01), namespace="tb3_0")
    spawned = flat_world.models["tb3_0"]
    assert spawned.namespace == "tb3_0"
    assert plugin_of(spawned, DiffDrive).element.findtext("robotNamespace") == "tb3_0"


DOOR = """<sdf version="{version}"><model name="door">
  <link name="frame"><collision name="c"><geometry><box><size>0.1 0.1 2</size></box></geometry></collision></link>
  <link name="panel">{panel}<collision name="c"><pose>0.5 0 1 0 0 0</pose>
    <geometry><box><size>1 0.05 2</size></box></geometry></collision></link>
  <joint name="hinge" type="{kind}"><parent>{parent}</parent><child>panel</child>
    <axis><xyz>0 0 1</xyz><limit><lower>-1.5</lower><upper>1.5</upper></limit></axis></joint>
</model></sdf>"""


@pytest.mark.parametrize("changes, message", [
    ({"kind": "universal"}, "joint 'hinge': type 'universal' is not simulated"),
    ({"kind": "hinge"}, "joint 'hinge': type 'hinge' is not an SDF joint type"),
    ({"parent": "frane"}, "joint 'hinge': <parent> 'frane' is not a link of the model"),
    ({"panel": "<pose>nan 0 0 0 0 0</pose>"}, "<pose>.*nan"),
    ({"panel": "<inertial><mass>-2</mass></inertial>"}, "link 'panel' of model 'door': <mass>: .*-2"),
    ({"panel": "<inertial><mass>1e300</mass></inertial>"}, "link 'panel' of model 'door': <mass>: .*1e.300"),
])
def test_bad_articulated_models_are_refused_in_one_line_and_the_simulation_goes_on(flat_world, tmp_path, changes,
                                                                                    message):
    values = {"version": "1.6", "kind": "revolute", "parent": "frame", "panel": ""}
    values.update(changes)
    before = flat_world.model_names()
    with pytest.raises(BridgeError, match=message) as error:
        spawned_sdf(flat_world, tmp_path, DOOR.format(**values), "door")
    assert "\n" not in str(error.value)
    assert flat_world.model_names() == before
    flat_world.step(10)


def test_joint_axes_follow_each_sdf_versions_frame_rules(tmp_path):
    """A joint posed 90 degrees about x: its axis "0 0 1" is the joint frame's z in 1.5 and 1.6 (and 1.7 without
    expressed_in), and the model frame's z, which is the joint frame's y, in 1.4, with use_parent_model_frame and
    with expressed_in="__model__". URDF's axis is in the joint frame."""
    def axis(version, xyz):
        text = f"""<sdf version="{version}"><world name="w"><model name="m">
          <link name="a"/><link name="b"/>
          <joint name="j" type="revolute"><parent>a</parent><child>b</child><pose>0 0 0 1.5707963267948966 0 0</pose>
            <axis>{xyz}<limit><lower>-1</lower><upper>1</upper></limit></axis></joint></model></world></sdf>"""
        path = tmp_path / f"axis_{version}.world"
        path.write_text(text)
        (robot,) = parse_world(str(path), []).robots
        return tuple(robot.robot.joints["j"].axis)
    assert axis("1.6", "<xyz>0 0 1</xyz>") == pytest.approx((0.0, 0.0, 1.0))
    assert axis("1.4", "<xyz>0 0 1</xyz>") == pytest.approx((0.0, 1.0, 0.0), abs=1e-9)
    assert axis("1.6", "<xyz>0 0 1</xyz><use_parent_model_frame>true</use_parent_model_frame>") == pytest.approx(
        (0.0, 1.0, 0.0), abs=1e-9)
    assert axis("1.7", "<xyz expressed_in='__model__'>0 0 1</xyz>") == pytest.approx((0.0, 1.0, 0.0), abs=1e-9)
    assert axis("1.7", "<xyz>0 0 1</xyz>") == pytest.approx((0.0, 0.0, 1.0))


def save(simulation, path):
    snapshot = take_snapshot(simulation, with_robots=False)
    write_world_file(str(path), world_sdf(simulation.world, snapshot.models, snapshot.poses, snapshot.robots,
                                          snapshot.link_states))
    return snapshot


def test_save_world_writes_articulated_models_back_with_their_joints_where_they_stand(pendulum, tmp_path, caplog):
    """The swinging pendulum saved and read back is the same model with its joints, at its model pose; its links'
    world poses go into the world's <state> as Gazebo saves them, and reading that puts the joints where they
    stood (a reset goes back to the model's own configuration, as Gazebo's). A NaN in the state is said and
    left out."""
    pendulum.reset(simulation=True)
    pendulum.set_model_configuration("double_pendulum", ["shoulder", "elbow"], [0.3, -0.2])
    pendulum.step(100)
    robot = pendulum.models["double_pendulum"].robot
    standing = [position for position, _, _ in robot.joint_state(["shoulder", "elbow"])]
    assert save(pendulum, tmp_path / "saved.world").robot_names == []
    saved = ET.parse(tmp_path / "saved.world").getroot().find("world")
    assert [joint.get("name") for joint in saved.findall("model[@name='double_pendulum']/joint")] == [
        "shoulder", "elbow"]
    assert [link.get("name") for link in saved.findall("state/model[@name='double_pendulum']/link")] == [
        "upper", "lower"]
    (reloaded,) = parse_world(str(tmp_path / "saved.world"), []).robots
    original = pendulum.sdf_robots["double_pendulum"]
    assert reloaded.pose.position == pytest.approx(original.pose.position, abs=1e-6)
    assert {name: (joint.type, joint.parent, joint.child) for name, joint in reloaded.robot.joints.items()} == {
        name: (joint.type, joint.parent, joint.child) for name, joint in original.robot.joints.items()}
    assert [reloaded.joint_positions[name] for name in ("shoulder", "elbow")] == pytest.approx(standing, abs=1e-5)
    with Simulation(parse_world(str(tmp_path / "saved.world"), []), CORE_PLUGINS) as again:
        model_frame = compose(again.engine.model_pose("double_pendulum"), inverse(reloaded.root_in_model))
        assert model_frame.position == pytest.approx(original.pose.position, abs=1e-6)
        robot_again = again.models["double_pendulum"].robot
        assert robot_again.movable_joints == ["shoulder", "elbow"]
        assert [p for p, _, _ in robot_again.joint_state(["shoulder", "elbow"])] == pytest.approx(standing, abs=1e-5)
        again.reset(simulation=False)
        assert [p for p, _, _ in robot_again.joint_state(["shoulder", "elbow"])] == pytest.approx([0, 0], abs=1e-9)
    tree = ET.parse(tmp_path / "saved.world")
    tree.find("world/state/model[@name='double_pendulum']/link[@name='lower']/pose").text = "nan 0 0 0 0 0"
    tree.write(tmp_path / "nan.world")
    caplog.clear()
    (unreached,) = parse_world(str(tmp_path / "nan.world"), []).robots
    assert unreached.joint_positions == {}
    assert "nan.world:" in caplog.text and "<state> of model 'double_pendulum' left out" in caplog.text


def test_a_link_on_no_joint_moves_freely_in_its_model_as_in_gazebo(flat_world, tmp_path):
    """A drawer cabinet with a loose box above it: the box is on no joint, so it falls on its own, and through the
    cabinet to the ground, since links of one model do not collide without <self_collide> (Gazebo's default)."""
    cabinet = """<sdf version="1.6"><model name="cabinet">
      <link name="body"><pose>0 0 0.25 0 0 0</pose>
        <collision name="c"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision></link>
      <link name="drawer"><pose>0.1 0 0.25 0 0 0</pose>
        <collision name="c"><geometry><box><size>0.4 0.4 0.1</size></box></geometry></collision></link>
      <link name="loose_box"><pose>0 0 1.5 0 0 0</pose>
        <collision name="c"><geometry><box><size>0.1 0.1 0.1</size></box></geometry></collision></link>
      <joint name="slide" type="prismatic"><parent>body</parent><child>drawer</child>
        <axis><xyz>1 0 0</xyz><limit><lower>0</lower><upper>0.3</upper></limit></axis></joint>
    </model></sdf>"""
    spawned_sdf(flat_world, tmp_path, cabinet, "cabinet", pose=(-5.0, 5.0, 0.0))
    robot = flat_world.models["cabinet"].robot
    assert robot.movable_joints == ["slide"]
    flat_world.step(1500)
    assert robot.link_world_pose("loose_box").position[2] == pytest.approx(0.05, abs=0.01)
    assert robot.link_world_pose("body").position[2] == pytest.approx(0.25, abs=0.01)


def test_a_ball_joint_swings_freely_in_every_direction(flat_world, tmp_path):
    """A rod hung from the world on a ball joint, started 0.3 rad off the vertical in x and y: it swings through
    the bottom, and a reset puts it back where it started."""
    rod = """<sdf version="1.6"><model name="ball_pendulum"><pose>5 5 2 0.3 0.3 0</pose>
      <link name="rod"><inertial><pose>0 0 -0.5 0 0 0</pose><mass>1</mass>
        <inertia><ixx>0.083</ixx><iyy>0.083</iyy><izz>0.001</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia>
        </inertial></link>
      <joint name="socket" type="ball"><parent>world</parent><child>rod</child></joint>
    </model></sdf>"""
    spawned_sdf(flat_world, tmp_path, rod, "ball_pendulum")
    robot = flat_world.models["ball_pendulum"].robot
    assert robot.movable_joints == []
    start = robot.link_world_pose("rod")
    lowest = min(_tilt(robot) for _ in range(40) if flat_world.step(10) is None)
    assert _tilt_of(start) == pytest.approx(0.42, abs=0.01) and lowest < 0.1
    assert robot.link_world_pose("rod").position == pytest.approx(start.position, abs=1e-4)  # the socket holds
    flat_world.reset(simulation=False)
    assert _tilt(robot) == pytest.approx(_tilt_of(start), abs=1e-6)


def _tilt_of(pose):
    """Angle between the rod (its link's -z) and the downward vertical."""
    down = np.array(rotation_matrix(pose.orientation)) @ np.array([0.0, 0.0, -1.0])
    return math.acos(max(-1.0, min(1.0, -down[2])))


def _tilt(robot):
    return _tilt_of(robot.link_world_pose("rod"))


def test_nested_models_and_sdf_1_7_frames_place_links_and_joints(tmp_path):
    """A 1.7 model: a hinge frame attached to the base, a nested model's panel hinged there (its joint posed
    relative_to the frame, its axis expressed in the model frame). Links of nested models are "inner::link"."""
    text = """<sdf version="1.7"><world name="w"><model name="cupboard"><pose>1 2 0 0 0 1.5707963267948966</pose>
      <link name="base"><pose>0 0 0.5 0 0 0</pose></link>
      <frame name="hinge_frame" attached_to="base"><pose relative_to="base">0.3 0.2 0 0 0 0</pose></frame>
      <model name="door"><pose relative_to="hinge_frame">0 0 0 0 0 0</pose>
        <link name="panel"><pose>0.1 0 0 0 0 0</pose></link>
      </model>
      <joint name="hinge" type="revolute"><parent>base</parent><child>door::panel</child>
        <pose relative_to="hinge_frame">0 0 0 0 0 0</pose>
        <axis><xyz expressed_in="__model__">1 0 0</xyz><limit><lower>0</lower><upper>1.5</upper></limit></axis>
      </joint></model></world></sdf>"""
    path = tmp_path / "cupboard.world"
    path.write_text(text)
    (cupboard,) = parse_world(str(path), []).robots
    joint = cupboard.robot.joints["hinge"]
    assert (joint.parent, joint.child) == ("base", "door::panel")
    # PyBullet composes poses in single precision.
    assert joint.origin.position == pytest.approx((0.3, 0.2, 0.0), abs=1e-6)  # the hinge frame, seen from base
    assert joint.axis == pytest.approx((1.0, 0.0, 0.0), abs=1e-6)  # the model's x, and no turn from model to joint
    with Simulation(parse_world(str(path), []), CORE_PLUGINS) as simulation:
        robot = simulation.models["cupboard"].robot
        # The panel's own frame (not its joint's): base (0, 0, 0.5) + hinge (0.3, 0.2, 0) + (0.1, 0, 0), turned by
        # 90 degrees.
        assert robot.link_world_pose("door::panel").position == pytest.approx((0.8, 2.4, 0.5), abs=1e-5)


def test_an_include_adds_its_plugins_to_the_model_it_includes(flat_world, tmp_path):
    """SDF 1.6's <include><plugin>: a rigid model:// box given ground truth by the world that includes it."""
    world = """<sdf version="1.6"><world name="default"><include><uri>model://versioned_box</uri>
      <plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>link</bodyName><topicName>box_truth</topicName>
      </plugin></include></world></sdf>"""
    spawned_sdf(flat_world, tmp_path, world, "tracked_box", pose=(-5.0, -5.0, 1.0))
    assert [type(plugin).__name__ for plugin in flat_world.models["tracked_box"].plugins] == ["P3D"]


# An arm hung from the world on a joint posed away from the arm's frame (moved and turned in the arm), with a
# laser on the arm and ground truth of the arm: what Gazebo reports for the arm is its own frame.
MODEL_POSE, ARM_POSE = ((5.0, -5.0, 2.0), (0.0, 0.0, 0.0)), ((0.1, 0.0, -0.3), (0.0, 0.0, 0.3))
PIVOT_POSE, LASER_POSE = ((0.0, 0.05, 0.3), (0.0, 0.0, 0.7)), ((0.05, 0.0, -0.2), (0.0, 0.3, 0.0))
OFFSET_PENDULUM = f"""<sdf version="1.6"><model name="offset_pendulum">
  <link name="arm"><pose>{" ".join(map(str, ARM_POSE[0] + ARM_POSE[1]))}</pose>
    <inertial><pose>0 0 -0.1 0 0 0</pose><mass>1</mass>
      <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.001</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
    <sensor name="laser" type="ray"><pose>{" ".join(map(str, LASER_POSE[0] + LASER_POSE[1]))}</pose>
      <ray><scan><horizontal><samples>5</samples><min_angle>-0.1</min_angle><max_angle>0.1</max_angle></horizontal>
      </scan><range><min>0.1</min><max>5</max></range></ray>
      <plugin name="laser" filename="libgazebo_ros_laser.so"><topicName>scan</topicName><frameName>arm</frameName>
      </plugin></sensor></link>
  <joint name="pivot" type="revolute"><parent>world</parent><child>arm</child>
    <pose>{" ".join(map(str, PIVOT_POSE[0] + PIVOT_POSE[1]))}</pose><axis><xyz>1 0 0</xyz></axis></joint>
  <plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>arm</bodyName><topicName>arm_truth</topicName>
    <frameName>world</frameName></plugin>
</model></sdf>"""


def _arm_frame(angle):
    """The arm's SDF frame in the world with the pivot turned by ``angle`` (the arm at rest turned about the pivot's
    axis, its x in SDF 1.6, through the pivot's origin), that axis and that origin, world."""
    arm = compose(pose_from_xyz_rpy(*MODEL_POSE), pose_from_xyz_rpy(*ARM_POSE))
    pivot = compose(arm, pose_from_xyz_rpy(*PIVOT_POSE))
    axis = np.array(rotation_matrix(pivot.orientation)) @ np.array([1.0, 0.0, 0.0])
    turn = Pose((0.0, 0.0, 0.0), tuple(axis * math.sin(angle / 2.0)) + (math.cos(angle / 2.0),))
    about_pivot = compose(Pose(pivot.position, IDENTITY.orientation),
                          compose(turn, Pose(tuple(-np.array(pivot.position)), IDENTITY.orientation)))
    return compose(about_pivot, arm), axis, np.array(pivot.position)


def test_a_link_whose_joint_has_a_pose_reports_its_own_frame_as_in_gazebo(flat_world, tmp_path):
    """PyBullet puts the arm's body frame at its joint; get_link_state, p3d and the arm's laser still see the
    arm's SDF frame, at rest and swinging (its origin moving about the pivot)."""
    spawned_sdf(flat_world, tmp_path, OFFSET_PENDULUM, "offset_pendulum", pose=MODEL_POSE[0])
    spawned = flat_world.models["offset_pendulum"]
    robot, truth = spawned.robot, plugin_of(spawned, P3D)
    laser = plugin_of(spawned, RaySensor)
    for setting in (None, 0.4):  # at rest as spawned, then set and swinging
        if setting is not None:
            flat_world.set_model_configuration("offset_pendulum", ["pivot"], [setting])
            flat_world.step(30)
        (angle, rate, _), = robot.joint_state(["pivot"])
        expected, axis, pivot = _arm_frame(angle)
        velocity = np.cross(axis * rate, np.array(expected.position) - pivot)
        pose, linear, angular = flat_world.link_state("offset_pendulum::arm", "world")
        ground_truth = truth.read(flat_world.sim_time)
        for measured in (pose, ground_truth.pose, robot.link_world_pose("arm")):
            assert measured.position == pytest.approx(expected.position, abs=1e-5)
            assert np.array(rotation_matrix(measured.orientation)) == pytest.approx(
                np.array(rotation_matrix(expected.orientation)), abs=1e-5)
        for measured in (linear, ground_truth.linear):
            assert measured == pytest.approx(velocity, abs=1e-4)
        assert angular == pytest.approx(axis * rate, abs=1e-4)
        sensor = compose(expected, pose_from_xyz_rpy(*LASER_POSE))
        assert laser.sensor_world_pose().position == pytest.approx(sensor.position, abs=1e-5)
    assert abs(rate) > 0.1  # swinging
    save(flat_world, tmp_path / "saved.world")
    saved = next(model for model in parse_world(str(tmp_path / "saved.world"), TEST_MODEL_PATH).robots
                 if model.name == "offset_pendulum")
    assert saved.joint_positions["pivot"] == pytest.approx(angle, abs=1e-5)
