"""apply_joint_effort and clear_joint_forces (core/joints/joint_efforts.py, Simulation.apply_joint_effort): an
effort spins a free turntable as τ/I predicts for its window, several add up, each is cut to the joint's effort
limit, and one on an arm held by effort controllers adds to the controllers' efforts; bad requests get upstream's
message or one naming the value, and nothing moves."""
import math

import pytest
from ros_control_fixtures import arm, start_controllers
from sensor_fixtures import world_simulation

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.errors import ModelError

PLATE_INERTIA = 0.01  # kg·m² about the turntable's axis
TURNTABLE = f"""<robot name="table">
  <link name="base_link">
    <inertial><mass value="50"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.6 0.6 0.2"/></geometry></collision>
  </link>
  <link name="plate">
    <inertial><mass value="1"/><inertia ixx="{PLATE_INERTIA}" iyy="{PLATE_INERTIA}" izz="{PLATE_INERTIA}" ixy="0"
      ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.02"/></geometry></collision>
  </link>
  <joint name="turntable" type="continuous"><parent link="base_link"/><child link="plate"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/><limit effort="0.05" velocity="100"/></joint>
</robot>"""
CRATE = """<model name="crate"><pose>2 0 0.15 0 0 0</pose><link name="link">
  <inertial><mass>4</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.3 0.3 0.3</size></box></geometry></collision>
</link></model>"""


@pytest.fixture
def table(tmp_path):
    sim = world_simulation(tmp_path, CRATE)
    spawned = sim.spawn_robot(parse_robot(TURNTABLE, "model 'table'"), "table")
    sim.step(200)  # settled on the ground
    return sim, spawned


def spin(spawned):
    return spawned.robot.joint_state(["turntable"])[0][1]


def test_an_effort_spins_the_turntable_for_its_window_and_several_add_up(table):
    sim, spawned = table
    start = sim.sim_time + 0.05
    sim.apply_joint_effort("turntable", 0.006, start, 0.2)
    sim.apply_joint_effort("table::turntable", 0.004, start, 0.2)  # scoped by its model: the same joint
    sim.step(40)
    assert spin(spawned) == pytest.approx(0.0, abs=1e-3)  # not started yet
    sim.step(400)
    # Upstream's window holds both ends: 201 steps of 1 ms. Slow, so PyBullet's drag (the README) stays small.
    expected = 0.01 * 0.201 / PLATE_INERTIA
    print(f"figure: turntable after 0.01 N·m for 0.2 s: {spin(spawned):.4f} rad/s (τ·t/I = {expected:.4f})")
    assert spin(spawned) == pytest.approx(expected, rel=0.02)
    assert not sim.joint_efforts.pending()  # ended


def test_each_effort_is_cut_to_the_joint_limit_and_clear_ends_it(table):
    sim, spawned = table
    sim.apply_joint_effort("turntable", 5.0, 0.0, -1.0)  # until cleared; the URDF limit is 0.05 N·m
    sim.step(100)
    assert spin(spawned) == pytest.approx(0.05 * 0.1 / PLATE_INERTIA, rel=0.02)
    sim.joint_efforts.clear_named("turntable")
    assert not sim.joint_efforts.pending()
    coasting = spin(spawned)
    sim.step(100)
    assert spin(spawned) == pytest.approx(coasting, rel=0.01)


def test_a_reset_or_deletion_ends_the_efforts(table):
    sim, spawned = table
    sim.apply_joint_effort("turntable", 0.1, 0.0, -1.0)
    sim.reset(simulation=False)
    assert not sim.joint_efforts.pending()
    sim.apply_joint_effort("turntable", 0.1, 0.0, -1.0)
    sim.delete("table")
    assert not sim.joint_efforts.pending()
    sim.step(10)


@pytest.mark.parametrize("joint, effort, start, duration, message", [
    ("no_such_joint", 1.0, 0.0, 1.0, "^ApplyJointEffort: joint not found$"),
    ("crate::turntable", 1.0, 0.0, 1.0, "^ApplyJointEffort: joint not found$"),  # another model's scope
    ("table::", 1.0, 0.0, 1.0, "^ApplyJointEffort: joint not found$"),
    ("", 1.0, 0.0, 1.0, "^ApplyJointEffort: joint not found$"),
    ("turntable", math.nan, 0.0, 1.0, "effort must be finite and at most 1e\\+06 in size; got nan"),
    ("turntable", math.inf, 0.0, 1.0, "effort must be finite"),
    ("turntable", -1e300, 0.0, 1.0, "effort must be finite"),
    ("turntable", 1.0, math.nan, 1.0, "start_time and duration must be finite"),
    ("turntable", 1.0, 1e308, 1.0, "start_time and duration must be finite"),
    ("turntable", 1.0, 0.0, -math.inf, "start_time and duration must be finite"),
])
def test_bad_requests_are_refused_and_nothing_moves(table, joint, effort, start, duration, message):
    sim, spawned = table
    before = (sim.engine.model_pose("crate"), sim.engine.model_pose("table"), spin(spawned))
    with pytest.raises(ModelError, match=message):
        sim.apply_joint_effort(joint, effort, start, duration)
    assert not sim.joint_efforts.pending()
    sim.step(50)
    assert sim.engine.model_pose("crate").position == pytest.approx(before[0].position, abs=1e-6)
    assert spin(spawned) == pytest.approx(before[2], abs=1e-6)


def test_an_effort_adds_to_what_the_controllers_write():
    """A 4 N·m push on the elbow of an arm held by effort PIDs bends it by about what the PID's stiffness
    gives; were the controllers' efforts replaced, the arm would fold under gravity."""
    sim, spawned, plugin = arm("Effort")
    start_controllers(sim, plugin, "shoulder_position_controller", "elbow_position_controller")
    sim.step(1000)
    held = spawned.robot.joint_state(["elbow"])[0][0]
    sim.apply_joint_effort("elbow", 4.0, 0.0, 0.5)
    sim.step(300)
    bent = spawned.robot.joint_state(["elbow"])[0][0] - held
    # The PID's p is 500 N·m/rad; its integral (at most i_clamp, 2 N·m) takes up part of the push.
    print(f"figure: elbow under a 4 N·m push on its effort PID: {bent:.2e} rad")
    assert 2.0 / 500 <= bent <= 4.0 / 500 * 1.2
    sim.step(1500)
    assert spawned.robot.joint_state(["elbow"])[0][0] == pytest.approx(held, abs=1e-3)
