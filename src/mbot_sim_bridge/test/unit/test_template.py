"""libgazebo_ros_template.so (core/template.py), gazebo_plugins' template: it loads, says an unknown tag once,
and changes nothing in the simulation, as upstream's does nothing."""
import logging

from sensor_fixtures import plugin_of, world_simulation

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.template import Template

ROBOT = """<robot name="box">
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <gazebo><plugin name="template" filename="libgazebo_ros_template.so"><speed>1</speed></plugin></gazebo>
</robot>"""


def test_the_template_loads_and_does_nothing(tmp_path, caplog):
    sim = world_simulation(tmp_path)
    with caplog.at_level(logging.WARNING):
        spawned = sim.spawn_robot(parse_robot(ROBOT, "model 'box'"), "box", pose_from_xyz_rpy((0, 0, 0.1), (0, 0, 0)))
    assert plugin_of(spawned, Template).label == "GazeboRosTemplate(ns = box)"
    assert "speed" in caplog.text
    sim.step(200)  # resting on the ground
    before = spawned.robot.root_pose()
    sim.step(500)
    after = spawned.robot.root_pose()
    assert max(abs(a - b) for a, b in zip(before.position, after.position)) < 1e-4
