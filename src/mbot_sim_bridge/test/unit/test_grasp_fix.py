"""libgazebo_grasp_fix.so (core/manipulation/grasp_fix.py): upstream's grip check; two fingers closing on a box
attach it to the palm after grip_count_threshold updates, with disable_collisions_on_attach it collides with
nothing meanwhile, a reset releases it and restores its collisions; arms the robot cannot have refuse the spawn.
The pick with the workspace's arm is in test_grasp_pick.py."""
import math

import numpy as np
import pytest
from plugin_robots import MIMIC_GRIPPER
from sensor_fixtures import world_simulation

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.manipulation.grasp_fix import GraspFix, grips

GRASP_FIX = """<gazebo><plugin name="grasp_fix" filename="libgazebo_grasp_fix.so">
  {arm}<update_rate>20</update_rate><max_grip_count>4</max_grip_count><grip_count_threshold>2</grip_count_threshold>
  <forces_angle_tolerance>120</forces_angle_tolerance><release_tolerance>0.005</release_tolerance>
  <disable_collisions_on_attach>true</disable_collisions_on_attach></plugin></gazebo>"""
ARM = ("<arm><arm_name>hand</arm_name><palm_link>{palm}</palm_link><gripper_link>left_finger</gripper_link>"
       "<gripper_link>right_finger</gripper_link></arm>")
MIMIC = '<mimic joint="left_finger_joint" multiplier="-1"/>'
# A 6 cm cube between the open fingers (their inner faces 4 cm from the centre line), resting on the palm.
CUBE = """<model name="cube"><pose>0 0 0.135 0 0 0</pose><link name="link">
  <inertial><mass>0.1</mass><inertia><ixx>6e-5</ixx><iyy>6e-5</iyy><izz>6e-5</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.06 0.06 0.06</size></box></geometry></collision></link></model>"""


def test_two_forces_grip_when_they_oppose_within_the_tolerance_and_the_weaker_is_at_least_0_3_of_the_other():
    tolerance = math.radians(120)
    left, right = np.array([0.0, -2.0, 0.0]), np.array([0.0, 2.0, 0.0])
    assert grips([left, right], tolerance)
    assert grips([left, np.array([0.0, 0.6, -0.1])], tolerance)
    assert not grips([left, np.array([0.0, 0.5, 0.0])], tolerance)  # 0.25 of the other
    assert not grips([left, np.array([2.0, 0.0, 0.0])], tolerance)  # 90 degrees apart
    assert not grips([left, np.array([0.0, 1e-5, 0.0])], tolerance)  # negligible
    assert not grips([left], tolerance)


def gripper(tmp_path, palm="palm"):
    sim = world_simulation(tmp_path, CUBE)
    urdf = MIMIC_GRIPPER.format(mimic=MIMIC, plugin=GRASP_FIX.format(arm=ARM.format(palm=palm)))
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'gripper'"), "gripper")
    sim.step(300)
    return sim, spawned, next(plugin for plugin in spawned.plugins if isinstance(plugin, GraspFix))


def cube_contacts(sim):
    return sim.engine.client.getContactPoints(bodyA=sim.engine.body_of("cube"))


def test_closing_fingers_attach_the_cube_without_collisions_and_a_reset_releases_it(tmp_path):
    sim, spawned, plugin = gripper(tmp_path)
    try:
        assert not plugin.attached and cube_contacts(sim)  # on the palm
        spawned.robot.set_joint_position("left_finger_joint", -0.02, 20.0)
        for _ in range(100):
            sim.step(10)
            if plugin.attached:
                break
        assert list(plugin.attached) == [("cube", "link")]
        assert plugin.counts[("cube", "link")] == 3  # attached on the update after the count passed 2
        sim.step(10)
        assert not cube_contacts(sim)  # disable_collisions_on_attach
        sim.reset(simulation=False)
        assert not plugin.attached and not plugin.joints.holds("hand")
        sim.step(100)
        assert cube_contacts(sim)  # collides again, back on the palm
    finally:
        sim.close()


@pytest.mark.parametrize("arm, words", [
    ("", "without any <arm> declarations"),
    ("<arm><arm_name>hand</arm_name><palm_link>palm</palm_link></arm>", "at least one <gripper_link>"),
    (ARM.format(palm="no_such_link"), "link no_such_link is not a link of model 'gripper'"),
    (ARM.format(palm="palm") * 2, "arm named hand was already added")])
def test_arms_the_robot_cannot_have_refuse_the_spawn_in_one_line(tmp_path, arm, words):
    sim = world_simulation(tmp_path)
    try:
        urdf = MIMIC_GRIPPER.format(mimic=MIMIC, plugin=GRASP_FIX.format(arm=arm))
        with pytest.raises(ConfigError, match=words) as refusal:
            sim.spawn_robot(parse_robot(urdf, "model 'gripper'"), "gripper")
        assert "\n" not in str(refusal.value)
        assert sim.model_names() == ["ground_plane"]
    finally:
        sim.close()
