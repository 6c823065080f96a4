"""Wheel and ground contact: lumped fixed-joint parts keep their own surface (a frictionless caster under a
chassis with friction), wheels touch the ground at their mid-plane, and wheels that carry fdir1 get the wheel
contact model (core/wheel_contact.py), so a ros_control differential base tracks its commands and skid-steer
bases turn in place alike both ways, steadily, at any heading; with its mass off centre, as Clearpath's published
Husky, a base moves as the balance of its contacts' forces says (skid_steer_balance.py, solved apart from the
simulator). Ground truth from the core's root pose. MBOT_LONG_TESTS=1 runs every turn over 10 s."""
import math
import os
from xml.etree import ElementTree

import numpy as np
import pytest
from ros_control_fixtures import ROBOTS, WORKSPACE_SRC, load_yaml, simulate, start_controllers
from sensor_fixtures import expanded, measured_motion
from skid_steer_balance import SkidBase, steady_twist

from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import rpy, yaw
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.wheel_contact import _outside
from mbot_sim_bridge.package_uris import resolve_package_uris

LONG = os.environ.get("MBOT_LONG_TESTS") == "1"
CASTER_CONTROL = os.path.join(ROBOTS, "config", "caster_control.yaml")
HUSKY = {"wheel_radius": "0.1651", "wheel_width": "0.1143", "track": "0.5708", "wheelbase": "0.512",
         "base_mass": "46.034", "wheel_mass": "2.637"}
# Where Clearpath's published Husky puts its base's centre of mass (inertial_link, in base_link): 8.5 cm right.
HUSKY_BASE_COM = (-0.00065, -0.085, 0.062)


def caster_base_urdf():
    return expanded(os.path.join(ROBOTS, "urdf", "caster_base.urdf.xacro"))


@pytest.fixture(scope="module")
def caster_base():
    sim, spawned, plugin = simulate(caster_base_urdf(), load_yaml(CASTER_CONTROL), "caster_base", namespace="/")
    controller = start_controllers(sim, plugin, "mobile_base_controller", "joint_state_controller")
    yield sim, spawned, controller
    sim.close()


def test_a_lumped_caster_keeps_its_own_surface_and_the_chassis_its_own(caster_base):
    sim, spawned, _ = caster_base
    robot = spawned.robot
    assert robot.model.lumped_into["caster_link"][0] == robot.model.lumped_into["laser_link"][0] == "base_link"
    assert "caster_link" not in robot.link_index  # Gazebo has no such link
    friction = {name: robot.client.getDynamicsInfo(robot.body, index)[1]
                for name, index in {**robot.link_index, **robot.surface_link_index}.items()}
    # The chassis (and the lidar lumped with it) keeps mu 1, the caster its 0; the wheels (no fdir1) Bullet's 1.
    assert friction == {"base_link": 1.0, "caster_link": 0.0, "left_wheel_link": 1.0, "right_wheel_link": 1.0}
    names = sim.engine.collision_names[robot.body]
    assert names[robot.surface_link_index["caster_link"]] == \
        "caster_base::base_link::base_link_fixed_joint_lump__caster_link_collision"
    assert names[-1] == "caster_base::base_link::base_link_collision"


def test_lumped_parts_keep_the_mass_where_gazebo_puts_it(caster_base):
    _, spawned, _ = caster_base
    info = spawned.robot.client.getDynamicsInfo(spawned.robot.body, -1)
    # 8 kg box, 0.05 kg caster 0.15 m behind and 0.025 m below, 0.15 kg lidar 0.03 m behind and 0.06 m above.
    assert info[0] == pytest.approx(8.2)
    assert spawned.robot.root_from_com.position[0] == pytest.approx((0.05 * 0.15 + 0.15 * 0.03) / 8.2, abs=1e-6)
    assert spawned.robot.client.getDynamicsInfo(spawned.robot.body,
                                                spawned.robot.surface_link_index["caster_link"])[0] < 1e-6


@pytest.mark.parametrize("linear, angular", [(0.3, 0.0), (-0.2, 0.0), (0.0, 0.8), (0.0, -0.8)])
def test_the_caster_base_tracks_within_5_percent_and_stays_level(caster_base, linear, angular):
    sim, spawned, controller = caster_base
    speed, yaw_rate = measured_motion(sim, spawned, lambda: controller.set_command(linear, angular, sim.sim_time))
    roll, pitch, _ = rpy(spawned.robot.root_pose().orientation)
    print(f"figure: caster base ({linear} m/s, {angular} rad/s) -> ({speed:.4f} m/s, {yaw_rate:.4f} rad/s), "
          f"tilt {math.degrees(math.hypot(roll, pitch)):.3f} deg")
    if linear:
        assert speed == pytest.approx(linear, rel=0.05) and abs(yaw_rate) < 0.01
    else:
        assert yaw_rate == pytest.approx(angular, rel=0.05) and abs(speed) < 0.01
    assert math.degrees(math.hypot(roll, pitch)) < 0.5


# -- skid steering ---------------------------------------------------------------------------------------------
def _rover():
    urdf = expanded(os.path.join(WORKSPACE_SRC, "rover_description", "urdf", "rover.urdf.xacro"),
                        lidar_3d_enabled="false")
    controllers = load_yaml(os.path.join(WORKSPACE_SRC, "rover_control", "config", "control.yaml"))
    return urdf, controllers, "rover_velocity_controller", "rover_joint_publisher"


def _husky_quad(**arguments):
    urdf = expanded(os.path.join(ROBOTS, "urdf", "quad_base.urdf.xacro"), **HUSKY, **arguments)
    controllers = load_yaml(os.path.join(ROBOTS, "config", "quad_control.yaml"))
    assert controllers["quad_velocity_controller"]["wheel_separation_multiplier"] == 1.875
    return urdf, controllers, "quad_velocity_controller", "quad_joint_publisher"


@pytest.fixture(scope="module", params=["rover", "husky_quad"])
def skid_base(request):
    urdf, controllers, velocity_controller, joint_publisher = {"rover": _rover, "husky_quad": _husky_quad}[
        request.param]()
    sim, spawned, plugin = simulate(urdf, controllers, request.param, package_uris=resolve_package_uris,
                                    namespace="/")
    controller = start_controllers(sim, plugin, velocity_controller, joint_publisher)
    sim.step(2000)  # the rover is spawned with its wheels in the ground, as Husky's launch spawns Husky
    yield request.param, sim, spawned, controller
    sim.close()


def turn_windows(sim, spawned, controller, linear, angular, seconds):
    """Ground-truth yaw rates over consecutive 1 s windows after 1.5 s at the command, and the mean speed."""
    measured_motion(sim, spawned, lambda: controller.set_command(linear, angular, sim.sim_time), settle=1.5,
                    window=0.05)
    yaws, speeds = [yaw(spawned.robot.root_pose().orientation)], []
    for step in range(int(seconds * 20)):
        controller.set_command(linear, angular, sim.sim_time)
        sim.step(50)
        velocity, _ = spawned.robot.root_velocity()
        heading = yaw(spawned.robot.root_pose().orientation)
        speeds.append(velocity[0] * math.cos(heading) + velocity[1] * math.sin(heading))
        if step % 20 == 19:
            yaws.append(heading)
    return np.diff(np.unwrap(yaws)), float(np.mean(speeds))


@pytest.mark.parametrize("angular", [0.3, 0.5, 1.0])
def test_turns_in_place_within_10_percent_alike_both_ways_and_steadily(skid_base, angular):
    name, sim, spawned, controller = skid_base
    seconds = 10 if LONG or angular == 0.5 else 3
    rates = {}
    for command in (angular, -angular):
        windows, speed = turn_windows(sim, spawned, controller, 0.0, command, seconds)
        rates[command] = windows.mean()
        print(f"figure: {name} turning in place at {command:+.1f} rad/s: {windows.mean():+.3f} rad/s over {seconds} s "
              f"(1 s windows {windows.min():+.3f} to {windows.max():+.3f}), speed {speed:+.4f} m/s")
        assert windows.mean() == pytest.approx(command, rel=0.10)
        assert (windows / command).min() > 0.8
        assert abs(speed) < 0.02
    assert abs(rates[angular] + rates[-angular]) < 0.03 * abs(rates[angular])


@pytest.mark.parametrize("angular", [0.5, -0.5])
def test_arcs_within_10_percent(skid_base, angular):
    name, sim, spawned, controller = skid_base
    windows, speed = turn_windows(sim, spawned, controller, 0.3, angular, 2)
    print(f"figure: {name} arc (0.3 m/s, {angular:+.1f} rad/s): {speed:.3f} m/s, {windows.mean():+.3f} rad/s")
    assert windows.mean() == pytest.approx(angular, rel=0.10)
    assert speed == pytest.approx(0.3, rel=0.10)


@pytest.fixture(scope="module")
def husky_mass_off_centre():
    urdf, controllers, velocity_controller, joint_publisher = _husky_quad(
        base_com=" ".join(str(value) for value in HUSKY_BASE_COM))
    sim, spawned, plugin = simulate(urdf, controllers, "husky_quad", namespace="/")
    controller = start_controllers(sim, plugin, velocity_controller, joint_publisher)
    sim.step(1000)
    yield sim, spawned, controller
    sim.close()


def husky_balance() -> SkidBase:
    """The Husky-sized base with Husky's mass distribution, for the balance model: the base's mass at its centre
    of mass, each wheel's at its axle (base_link, on the axles, is a wheel radius above the ground)."""
    radius, base_mass, wheel_mass = (float(HUSKY[key]) for key in ("wheel_radius", "base_mass", "wheel_mass"))
    mass = base_mass + 4 * wheel_mass
    x, y, z = HUSKY_BASE_COM
    height = (base_mass * (radius + z) + 4 * wheel_mass * radius) / mass
    return SkidBase(float(HUSKY["wheelbase"]), float(HUSKY["track"]), mass,
                    (base_mass * x / mass, base_mass * y / mass, height))


@pytest.mark.parametrize("linear, angular", [(0.3, 0.5), (0.3, -0.5), (0.0, 0.5), (0.0, -0.5), (0.0, 1.0),
                                             (0.0, -1.0)])
def test_with_the_mass_off_centre_a_base_moves_as_its_contacts_forces_balance(husky_mass_off_centre, linear,
                                                                                angular):
    """Arcs and turns of a base loaded 1.6 times harder on its right wheels than on its left: the steady state of
    Coulomb friction at the four contacts (mu 1, loads from the mass distribution and the turn's inertia), solved
    apart from the simulator, gives the speed and yaw rate; the arcs are unlike both ways because of it."""
    sim, spawned, controller = husky_mass_off_centre
    windows, speed = turn_windows(sim, spawned, controller, linear, angular, 1)
    expected_speed, _, expected_yaw_rate = steady_twist(husky_balance(), linear, angular, 1.875)
    print(f"figure: Husky's mass distribution ({linear} m/s, {angular:+.1f} rad/s): {speed:+.4f} m/s, "
          f"{windows.mean():+.4f} rad/s; balance of the contacts' forces {expected_speed:+.4f} m/s, "
          f"{expected_yaw_rate:+.4f} rad/s")
    assert speed == pytest.approx(expected_speed, abs=0.002)
    assert windows.mean() == pytest.approx(expected_yaw_rate, rel=0.005)


# -- the model's inputs ----------------------------------------------------------------------------------------
def test_the_friction_limit_is_an_ellipse_and_a_zero_mu_admits_no_force():
    assert not _outside(0.6, 0.8, 1.0, 1.0) and _outside(0.61, 0.8, 1.0, 1.0)
    assert not _outside(1.9, 0.0, 2.0, 0.5) and _outside(0.0, 0.6, 2.0, 0.5)
    assert _outside(0.0, 1e-9, 1.0, 0.0) and not _outside(0.5, 0.0, 1.0, 0.0)


@pytest.mark.parametrize("fdir1, message", [("nan 0 0", "NaN"), ("1 inf 0", "infinity"), ("1 0", "3 numbers"),
                                            ("x y z", "3 numbers")])
def test_a_bad_fdir1_is_refused_in_one_line(fdir1, message):
    urdf = caster_base_urdf().replace("<mu1>1</mu1>", f"<mu1>1</mu1><fdir1>{fdir1}</fdir1>", 1)
    model = parse_robot(urdf, "model 'caster_base'")
    with pytest.raises(ModelError, match=f"<gazebo reference='left_wheel_link'> <fdir1> '{fdir1}': .*{message}"):
        model.fdir1("left_wheel_link", "model 'caster_base'")


@pytest.mark.parametrize("mu", ["nan", "inf", "-1", "lots"])
def test_a_bad_mu_is_refused_in_one_line(mu):
    with pytest.raises(ModelError, match=f"<gazebo reference='caster_link'> <mu1> '{mu}'"):
        parse_robot(caster_base_urdf().replace("<mu1>0</mu1>", f"<mu1>{mu}</mu1>"), "model 'caster_base'")


def test_only_wheels_with_fdir1_get_the_model_and_every_wheel_a_tread(caster_base, skid_base):
    _, sim, spawned, _ = skid_base
    assert sorted(sim.engine._wheels[spawned.robot.body].wheels) == sorted(
        index for name, index in spawned.robot.link_index.items() if name.endswith("wheel_link"))
    caster_sim, caster, _ = caster_base
    assert caster.robot.body not in caster_sim.engine._wheels
    treads = ElementTree.fromstring(caster.robot.model.pybullet_urdf).findall(
        "link[@name='left_wheel_link']/collision/geometry/cylinder")
    assert [(float(c.get("radius")), float(c.get("length"))) for c in treads] == [(0.05, 0.002), (0.0495, 0.03)]


def test_a_huge_fdir1_is_a_direction_and_fdir1_off_a_wheel_is_said_once(caplog):
    urdf = caster_base_urdf().replace("<mu1>1</mu1>", "<mu1>1</mu1><fdir1>1e308 1e308 0</fdir1>", 1)
    urdf = urdf.replace("<mu1>0</mu1>", "<mu1>0</mu1><fdir1>1 0 0</fdir1>")
    model = parse_robot(urdf, "model 'caster_base'")
    assert model.fdir1("left_wheel_link", "x") == pytest.approx((math.sqrt(0.5), math.sqrt(0.5), 0.0))
    sim, spawned, plugin = simulate(urdf, load_yaml(CASTER_CONTROL), "caster_base", namespace="/")
    sim.step(200)
    assert "link 'caster_link' <fdir1> acts on wheels only" in caplog.text
    assert all(math.isfinite(value) for value in spawned.robot.root_pose().position)
    sim.close()


@pytest.mark.parametrize("mu1, mu2", [("1e308", "1e308"), ("1e308", "0"), ("0", "1e-300")])
def test_huge_and_tiny_wheel_friction_keeps_the_robot_finite(caplog, mu1, mu2):
    urdf = caster_base_urdf().replace("<mu1>1</mu1>", f"<mu1>{mu1}</mu1><fdir1>1 0 0</fdir1>").replace(
        "<mu2>1</mu2>", f"<mu2>{mu2}</mu2>")
    sim, spawned, plugin = simulate(urdf, load_yaml(CASTER_CONTROL), "caster_base", namespace="/")
    controller = start_controllers(sim, plugin, "mobile_base_controller")
    speed, _ = measured_motion(sim, spawned, lambda: controller.set_command(0.3, 0.8, sim.sim_time), settle=1.0,
                               window=0.5)
    # Not frozen back at its spawn pose by a NaN state: it drives (a wheel with mu 0 along fdir1 only slides).
    assert "made its state NaN" not in caplog.text and all(
        math.isfinite(value) for value in spawned.robot.root_pose().position)
    assert speed > 0.1 or mu1 == "0"
    assert sim.engine._wheels[spawned.robot.body].wheels
    if mu1 == "1e308":
        assert "a wheel's friction is taken as at most 1000" in caplog.text
    sim.close()
