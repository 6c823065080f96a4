"""Shared builders for the sensor tests: the core plugin registry, worlds with a wall or a box, and the
course's mbot with an IMU, p3d and their sensors added the way a Gazebo user writes them."""
import math
import os

from mbot_sim_bridge.core.geometry import yaw
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation

_WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="default">
  <gravity>0 0 -9.8</gravity>
  <physics type="ode"><max_step_size>0.001</max_step_size><real_time_factor>1</real_time_factor></physics>
  <model name="ground_plane"><static>true</static><link name="link">
    <collision name="c"><geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry></collision>
  </link></model>
  {models}
</world></sdf>
"""
_BOX = """<model name="{name}"><static>true</static><pose>{x} {y} {z} 0 0 0</pose><link name="link">
    <collision name="c"><geometry><box><size>{sx} {sy} {sz}</size></box></geometry></collision>
    <visual name="v"><geometry><box><size>{sx} {sy} {sz}</size></box></geometry>
      <material><ambient>{r} {g} {b} 1</ambient><diffuse>{r} {g} {b} 1</diffuse></material></visual>
  </link></model>"""


def box(name, centre, size, rgb=(0.7, 0.7, 0.7)) -> str:
    return _BOX.format(name=name, x=centre[0], y=centre[1], z=centre[2], sx=size[0], sy=size[1], sz=size[2],
                       r=rgb[0], g=rgb[1], b=rgb[2])


def world_simulation(tmp_path, *models, seed=0) -> Simulation:
    path = os.path.join(str(tmp_path), "sensors.world")
    with open(path, "w") as world:
        world.write(_WORLD.format(models="\n  ".join(models)))
    return Simulation(parse_world(path), CORE_PLUGINS, seed=seed)


def drive_motion(sim, spawned, plugin, linear, angular, settle, window=1.0):
    """A drive plugin's command (``set_command(linear, angular)``) held for ``settle`` s, then the robot's mean
    forward speed in its own frame and its heading change per second over ``window`` s (ground truth)."""
    plugin.set_command(linear, angular)
    sim.step(int(settle * 1000))
    speeds, heading0, start = [], yaw(spawned.robot.root_pose().orientation), sim.sim_time
    for _ in range(int(window * 20)):
        sim.step(50)
        velocity, _ = spawned.robot.root_velocity()
        heading = yaw(spawned.robot.root_pose().orientation)
        speeds.append(velocity[0] * math.cos(heading) + velocity[1] * math.sin(heading))
    turned = math.remainder(yaw(spawned.robot.root_pose().orientation) - heading0, 2 * math.pi)
    return sum(speeds) / len(speeds), turned / (sim.sim_time - start)


def plugin_of(spawned, plugin_class):
    return next(plugin for plugin in spawned.plugins if type(plugin) is plugin_class)


# An IMU board on a fixed joint (lumped into base_footprint, as TurtleBot3's imu_link), read three ways.
IMU_ADDITIONS = """
    <link name="imu_link"/>
    <joint name="imu_joint" type="fixed">
        <origin xyz="-0.03 0 0.07" rpy="0 0 0"/>
        <parent link="base_link"/>
        <child link="imu_link"/>
    </joint>
    <gazebo reference="imu_link">
        <sensor type="imu" name="imu">
            <always_on>true</always_on>
            <update_rate>200</update_rate>
            <imu>{noise}</imu>
            <plugin name="imu_sensor" filename="libgazebo_ros_imu_sensor.so">
                <topicName>imu_sensor</topicName>
                <frameName>imu_link</frameName>
                <updateRateHZ>100</updateRateHZ>
                <gaussianNoise>0.0</gaussianNoise>
            </plugin>
        </sensor>
    </gazebo>
    <gazebo>
        <plugin name="imu_plugin" filename="libgazebo_ros_imu.so">
            <alwaysOn>true</alwaysOn>
            <bodyName>imu_link</bodyName>
            <frameName>imu_link</frameName>
            <topicName>imu</topicName>
            <serviceName>imu_service</serviceName>
            <gaussianNoise>0.0</gaussianNoise>
            <updateRate>100</updateRate>
        </plugin>
        <plugin name="ground_truth" filename="libgazebo_ros_p3d.so">
            <bodyName>base_link</bodyName>
            <topicName>ground_truth</topicName>
            <frameName>world</frameName>
            <updateRate>50</updateRate>
        </plugin>
    </gazebo>
"""
ACCEL_NOISE = """<linear_acceleration><z><noise type="gaussian"><type>gaussian</type><mean>0</mean>
                <stddev>0.017</stddev></noise></z></linear_acceleration>"""


def course_urdf(name: str) -> str:
    """A Gazebo xacro of mbot_description expanded by the real xacro ("mbot_with_kinect_gazebo")."""
    source = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
    os.environ["ROS_PACKAGE_PATH"] = source + os.pathsep + os.environ.get("ROS_PACKAGE_PATH", "")
    import xacro_noetic as xacro
    return xacro.process_file(os.path.join(source, "mbot_description", "urdf", "gazebo", name + ".xacro")).toxml()


def with_imu(urdf: str, accel_noise: bool = False) -> str:
    return urdf.replace("</robot>", IMU_ADDITIONS.format(noise=ACCEL_NOISE if accel_noise else "") + "</robot>")
