"""apply_body_wrench and clear_body_wrenches (core/body_wrenches.py, Simulation.apply_body_wrench) and
libgazebo_ros_f3d.so (core/sensors/f3d.py): a crate held up by its weight's worth of force hovers and falls once the
wrench ends or is cleared; f3d reports the applied force on its link and nothing without one; a reference point
and a reference frame change the wrench as upstream's transform does; bad requests are refused."""
import math
import os

import pytest
from sensor_fixtures import plugin_of, world_simulation

from mbot_sim_bridge.core.body_wrenches import target_wrench
from mbot_sim_bridge.core.errors import ConfigError, ModelError
from mbot_sim_bridge.core.sensors.f3d import F3D
from mbot_sim_bridge.core.geometry import Pose, pose_from_xyz_rpy
from mbot_sim_bridge.core.description.robot_model import parse_robot

CRATE_MASS, GRAVITY = 4.0, 9.8
CRATE = f"""<model name="crate"><pose>0 0 1 0 0 0</pose><link name="link">
  <inertial><mass>{CRATE_MASS}</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.3 0.3 0.3</size></box></geometry></collision>
</link></model>"""
# The service tests' turntable (a base with a plate on a joint), with f3d on the plate.
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "..", "tests", "urdf",
                       "turntable.urdf")) as turntable:
    ARM = turntable.read().replace("</robot>", """<gazebo><plugin name="f3d" filename="libgazebo_ros_f3d.so">
    <bodyName>{body}</bodyName><topicName>plate_wrench</topicName><frameName>plate</frameName>
  </plugin></gazebo></robot>""")


def crate_height(sim):
    return sim.engine.model_pose("crate").position[2]


def test_a_crate_held_by_its_weight_hovers_until_the_wrench_ends_or_is_cleared(tmp_path):
    sim = world_simulation(tmp_path, CRATE)
    weight = (0.0, 0.0, CRATE_MASS * GRAVITY)
    sim.apply_body_wrench("crate::link", "", (0, 0, 0), weight, (0, 0, 0), 0.0, 0.5)
    sim.step(500)
    assert crate_height(sim) == pytest.approx(1.0, abs=1e-3)  # held for the 0.5 s
    sim.step(300)
    assert crate_height(sim) < 0.7  # then falls
    falling = crate_height(sim)
    sim.apply_body_wrench("crate::link", "world", (0, 0, 0), (0, 0, 3 * CRATE_MASS * GRAVITY), (0, 0, 0), 0.0, -1.0)
    sim.step(500)  # a net 2 g upwards, for ever
    rising = crate_height(sim)
    assert rising > falling + 0.1
    sim.clear_body_wrenches("crate::link")
    assert not sim.wrenches.pending()
    climb = sim.engine.model_velocity("crate")[0][2]
    sim.step(100)  # gravity alone again: 0.98 m/s slower after 0.1 s, and PyBullet's drag (the README)
    assert 0.98 < climb - sim.engine.model_velocity("crate")[0][2] < 1.2
    sim.close()


@pytest.mark.parametrize("simulation", [False, True])
def test_a_reset_ends_every_wrench_so_the_world_is_as_spawned(tmp_path, simulation):
    """Resets repair what service calls left (the README): a wrench "until cleared" ends with them too."""
    sim = world_simulation(tmp_path, CRATE)
    try:
        sim.apply_body_wrench("crate::link", "", (0, 0, 0), (0, 0, 3 * CRATE_MASS * GRAVITY), (0, 0, 0), 0.0, -1.0)
        sim.apply_body_wrench("crate::link", "", (0, 0, 0), (0, 0, 0), (0, 0, 1), 5.0, 1.0)
        sim.step(200)
        sim.reset(simulation)
        assert not sim.wrenches.pending()
        sim.step(1000)
        assert crate_height(sim) == pytest.approx(0.15, abs=1e-3)  # fell onto the ground and rests there
    finally:
        sim.close()


def test_f3d_reports_the_applied_force_and_nothing_without_one(tmp_path):
    sim = world_simulation(tmp_path)
    spawned = sim.spawn_robot(parse_robot(ARM.format(body="plate"), "model 'arm'"), "arm")
    f3d = plugin_of(spawned, F3D)
    sim.step(5)
    assert (f3d.latest.force, f3d.latest.torque) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    sim.apply_body_wrench("arm::plate", "", (0, 0, 0), (2.0, 0.0, 0.0), (0.0, 0.0, 0.5), sim.sim_time + 0.01, 0.1)
    sim.step(5)
    assert f3d.latest.force == (0.0, 0.0, 0.0)  # not yet started
    sim.step(20)
    print(f"figure: f3d on a plate with 2 N applied along x: {f3d.latest.force} N, {f3d.latest.torque} N·m")
    assert f3d.latest.force == pytest.approx((2.0, 0.0, 0.0))
    assert f3d.latest.torque == pytest.approx((0.0, 0.0, 0.5))
    sim.step(200)
    assert f3d.latest.force == (0.0, 0.0, 0.0)  # the 0.1 s are over
    sim.close()


def test_the_reference_point_and_frame_transform_the_wrench_as_upstream():
    body = pose_from_xyz_rpy((1.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    # The torque gains reference_point x force; a world frame keeps both as given.
    assert target_wrench((0, 0, 10), (0, 0, 0), (0, 1, 0), body, None) == ((0.0, 0.0, 10.0), (10.0, 0.0, 0.0))
    # A frame turned 90 degrees about z at the body: the force turns with it (and is then applied in the world).
    frame = pose_from_xyz_rpy((1.0, 0.0, 0.0), (0.0, 0.0, math.pi / 2))
    force, torque = target_wrench((1, 0, 0), (0, 0, 0), (0, 0, 0), body, frame)
    assert force == pytest.approx((0.0, 1.0, 0.0))
    assert torque == pytest.approx((0.0, 0.0, 0.0))
    # A frame 1 m above the body: the torque gains (frame position relative to the body) x force.
    above = Pose((1.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0))
    assert target_wrench((1, 0, 0), (0, 0, 0), (0, 0, 0), body, above)[1] == pytest.approx((0.0, 1.0, 0.0))


def test_bad_requests_are_refused_and_change_nothing(tmp_path):
    sim = world_simulation(tmp_path, CRATE)
    with pytest.raises(ModelError, match="ApplyBodyWrench: body does not exist: 'crate::lid' \\(crate::link\\)"):
        sim.apply_body_wrench("crate::lid", "", (0, 0, 0), (1, 0, 0), (0, 0, 0), 0.0, 1.0)
    with pytest.raises(ModelError, match="reference_frame 'nowhere' is not a valid entity name"):
        sim.apply_body_wrench("crate::link", "nowhere", (0, 0, 0), (1, 0, 0), (0, 0, 0), 0.0, 1.0)
    for force in ((math.nan, 0, 0), (math.inf, 0, 0), (1e300, 0, 0)):
        with pytest.raises(ModelError, match="must be finite and at most"):
            sim.apply_body_wrench("crate::link", "", (0, 0, 0), force, (0, 0, 0), 0.0, 1.0)
    assert not sim.wrenches.pending()
    sim.close()


@pytest.mark.parametrize("start, duration", [(math.nan, 1.0), (math.inf, 1.0), (-math.inf, 1.0), (1e308, 1.0),
                                             (0.0, math.nan), (0.0, math.inf), (0.0, -math.inf), (0.0, -1e308)])
def test_a_start_time_or_duration_no_ros_time_holds_is_refused(tmp_path, start, duration):
    """A start of 1e308 s overflowed the loop's count of steps to it; NaN or inf would never start or end."""
    sim = world_simulation(tmp_path, CRATE)
    with pytest.raises(ModelError, match=r"start_time and duration must be finite and at most 4\.29497e\+09 s"):
        sim.apply_body_wrench("crate::link", "", (0, 0, 0), (1, 0, 0), (0, 0, 0), start, duration)
    assert not sim.wrenches.pending()


def test_the_latest_ros_time_is_a_start_the_loop_waits_for(tmp_path):
    sim = world_simulation(tmp_path, CRATE)
    sim.apply_body_wrench("crate::link", "", (0, 0, 0), (1e3, 0, 0), (0, 0, 0), 2.0 ** 32 - 1e-9, -2.0 ** 31)
    assert sim.wrenches.pending()
    sim.step(50)
    assert sim.wrenches.applied_to("crate", "link") == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def test_f3d_on_a_link_lumped_away_is_refused(tmp_path):
    sim = world_simulation(tmp_path)
    with pytest.raises(ConfigError, match="bodyName: nowhere does not exist in model 'arm'"):
        sim.spawn_robot(parse_robot(ARM.format(body="nowhere"), "model 'arm'"), "arm")
    sim.close()
