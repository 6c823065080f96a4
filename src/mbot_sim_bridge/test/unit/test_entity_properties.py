"""get/set_link_properties and get/set_joint_properties (core/entity_properties.py): a link's mass and moments as
Bullet holds them, changed so a push turns the plate as τ·t/I predicts, gravity_mode false holds a crate up;
a joint's damping slows the plate as e^(-d·t/I), its stops and a velocity motor act; bad values get upstream's
message or one naming the value and change nothing; reset_world undoes it all."""
import math

import pytest
from gazebo_msgs.msg import ODEJointProperties
from sensor_fixtures import world_simulation
from test_joint_efforts import CRATE, PLATE_INERTIA, TURNTABLE

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose

LINK_NOT_FOUND = "link not found, did you forget to scope the link by model name?"


@pytest.fixture
def world(tmp_path):
    sim = world_simulation(tmp_path, CRATE.replace("<pose>2 0 0.15", "<pose>2 0 1"))
    table = sim.spawn_robot(parse_robot(TURNTABLE, "model 'table'"), "table")
    sim.step(10)
    return sim, table


def spin(table):
    return table.robot.joint_state(["turntable"])[0][1]


def test_link_properties_are_bullets_and_a_new_mass_and_moment_act(world):
    sim, table = world
    plate = sim.link_properties("table::plate")
    assert (plate.mass, plate.ixx, plate.iyy, plate.izz, plate.gravity_mode) == (1.0, 0.01, 0.01, 0.01, True)
    assert plate.com.position == pytest.approx((0, 0, 0), abs=1e-9)
    assert sim.link_properties("crate::link").mass == 4.0
    assert sim.link_properties("ground_plane::link").mass == 0.0
    sim.set_link_properties("table::plate", plate._replace(mass=2.0, izz=2 * PLATE_INERTIA))
    assert sim.link_properties("table::plate")[2:] == (2.0, 0.01, 0.0, 0.0, 0.01, 0.0, 2 * PLATE_INERTIA)
    sim.apply_joint_effort("turntable", 0.01, 0.0, 0.1)
    sim.step(200)
    assert spin(table) == pytest.approx(0.01 * 0.101 / (2 * PLATE_INERTIA), rel=0.02)


def test_gravity_mode_false_holds_a_crate_up_until_reset(world):
    sim, _ = world
    sim.set_model_state("crate", Pose((2.0, 0.0, 1.0), IDENTITY.orientation))  # at rest
    crate = sim.link_properties("crate::link")
    sim.set_link_properties("crate::link", crate._replace(gravity_mode=False))
    assert not sim.link_properties("crate::link").gravity_mode
    sim.step(500)
    assert sim.engine.model_pose("crate").position[2] == pytest.approx(1.0, abs=1e-3)
    sim.reset(simulation=False)
    assert sim.link_properties("crate::link").gravity_mode
    sim.step(500)
    assert sim.engine.model_pose("crate").position[2] < 0.5


@pytest.mark.parametrize("link, change, message", [
    ("table::lid", {}, "^SetLinkProperties: " + LINK_NOT_FOUND.replace("?", "\\?") + "$"),
    ("plate", {}, "^SetLinkProperties: " + LINK_NOT_FOUND.replace("?", "\\?") + "$"),
    ("table::plate", {"mass": math.nan}, "mass must be finite, above 0 and at most 1e\\+09 kg; got nan"),
    ("table::plate", {"mass": math.inf}, "mass must be finite"),
    ("table::plate", {"mass": 1e300}, "mass must be finite"),
    ("table::plate", {"mass": 0.0}, "mass must be finite, above 0"),
    ("table::plate", {"ixx": math.nan}, "inertia values must be finite"),
    ("table::plate", {"ixy": -1e300}, "inertia values must be finite"),
    ("table::plate", {"izz": -0.01}, "the inertia's moments must be above 0"),
    ("table::plate", {"com": Pose((math.inf, 0, 0), IDENTITY.orientation)}, "com must be finite"),
    ("table::plate", {"com": Pose((1e300, 0, 0), IDENTITY.orientation)}, "com must be finite"),
    ("ground_plane::link", {"mass": 5.0}, "model 'ground_plane' is static"),
])
def test_bad_link_properties_are_refused_and_change_nothing(world, link, change, message):
    sim, table = world
    before = sim.link_properties("table::plate"), sim.engine.model_pose("crate")
    with pytest.raises(ModelError, match=message):
        sim.set_link_properties(link, before[0]._replace(**change))
    assert sim.link_properties("table::plate") == before[0]
    assert sim.engine.model_pose("crate") == before[1]
    with pytest.raises(ModelError, match="^GetLinkProperties: " + LINK_NOT_FOUND.replace("?", "\\?") + "$"):
        sim.link_properties("table")


def test_a_moved_centre_of_mass_is_warned_about_and_the_mass_still_set(world, caplog):
    sim, _ = world
    plate = sim.link_properties("table::plate")
    sim.set_link_properties("table::plate", plate._replace(mass=3.0, com=Pose((0.1, 0, 0), IDENTITY.orientation)))
    assert sim.link_properties("table::plate").mass == 3.0
    assert "Bullet keeps a link's centre of mass and inertia axes" in caplog.text


def config(**fields):
    return ODEJointProperties(**{name: [value] for name, value in fields.items()})


def test_joint_damping_stops_and_a_velocity_motor_act_and_reset_world_undoes_them(world, caplog):
    sim, table = world
    assert sim.joint_properties("turntable") == (1, [0.0], [pytest.approx(0.0, abs=1e-3)],
                                                 [pytest.approx(0.0, abs=1e-3)])  # 1: CONTINUOUS
    sim.apply_joint_effort("turntable", 0.01, 0.0, 0.1)
    sim.step(110)
    before = spin(table)
    sim.set_joint_properties("table::turntable", config(damping=0.01, erp=0.2))
    assert "erp have no Bullet counterpart" in caplog.text
    assert sim.joint_properties("turntable").damping == [0.01]
    sim.step(500)
    decay = 0.01 * 0.5 / PLATE_INERTIA
    print(f"figure: damping 0.01 on the plate for 0.5 s: rate ×{spin(table) / before:.4f} (e^-{decay:g} = "
          f"{math.exp(-decay):.4f})")
    assert spin(table) == pytest.approx(before * math.exp(-decay), rel=0.03)
    sim.set_joint_properties("turntable", config(damping=0.0, vel=1.0, fmax=10.0))
    sim.step(100)
    assert spin(table) == pytest.approx(1.0, abs=1e-3)
    sim.set_joint_properties("turntable", config(vel=0.0, fmax=0.0, loStop=-0.3, hiStop=0.3))
    sim.apply_joint_effort("turntable", 0.001, 0.0, -1.0)
    sim.step(2000)  # free, it would turn 2 rad
    print(f"figure: turntable pushed against a hiStop of 0.3 rad: {table.robot.joint_state(['turntable'])[0][0]:.4f} "
          "rad after 2 s")
    assert table.robot.joint_state(["turntable"])[0][0] < 0.31
    sim.reset(simulation=False)
    assert sim.joint_properties("turntable").damping == [0.0]
    sim.set_joint_properties("turntable", config(vel=0.5, fmax=10.0))
    sim.step(5000)
    assert table.robot.joint_state(["turntable"])[0][0] > 2.0  # the stops are gone


@pytest.mark.parametrize("joint, fields, message", [
    ("no_such_joint", {}, "^SetJointProperties: joint not found$"),
    ("crate::turntable", {}, "^SetJointProperties: joint not found$"),
    ("turntable", {"damping": math.nan}, r"damping must be finite and in \[0, 1e\+06\]; got nan"),
    ("turntable", {"damping": -1.0}, "damping must be finite"),
    ("turntable", {"damping": 1e300}, "damping must be finite"),
    ("turntable", {"hiStop": math.inf}, "hiStop must be finite"),
    ("turntable", {"loStop": 0.5, "hiStop": 0.1}, "loStop 0.5 is above hiStop 0.1"),
    ("turntable", {"vel": -math.inf}, "vel must be finite"),
    ("turntable", {"fmax": -1.0}, "fmax must be finite"),
])
def test_bad_joint_properties_are_refused_and_change_nothing(world, joint, fields, message):
    sim, table = world
    with pytest.raises(ModelError, match=message):
        sim.set_joint_properties(joint, config(**fields))
    assert sim.joint_properties("turntable").damping == [0.0]
    sim.step(100)
    assert spin(table) == pytest.approx(0.0, abs=1e-3)
    with pytest.raises(ModelError, match="^GetJointProperties: joint not found$"):
        sim.joint_properties(joint if joint != "turntable" else "nothing")
