"""Shared builders for the sensor tests: the core plugin registry, worlds with a wall or a box, and the
course's mbot with an IMU, p3d and their sensors added the way a Gazebo user writes them."""
import functools
import math
import os

from mbot_sim_bridge.core.geometry import yaw
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.robot_description import expand_xacro

WORKSPACE_SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
# The workspace's packages for $(find ...) in the xacros, also outside the workspace's shell.
os.environ["ROS_PACKAGE_PATH"] = WORKSPACE_SRC + os.pathsep + os.environ.get("ROS_PACKAGE_PATH", "")

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


def measured_motion(sim, spawned, send_command, settle=1.5, window=1.0):
    """``send_command()`` every 50 ms of sim time (within any cmd_vel timeout) for ``settle`` s, then ground truth
    over ``window`` s more: the robot's mean forward speed in its own frame (a chord would shorten arcs) and its
    heading change per second."""
    forward_speeds = []

    def run(seconds, record):
        for _ in range(int(round(seconds / 0.05))):
            send_command()
            sim.step(50)
            if record:
                velocity, _ = spawned.robot.root_velocity()
                heading = yaw(spawned.robot.root_pose().orientation)
                forward_speeds.append(velocity[0] * math.cos(heading) + velocity[1] * math.sin(heading))
    run(settle, False)
    start, heading0 = sim.sim_time, yaw(spawned.robot.root_pose().orientation)
    run(window, True)
    turned = math.remainder(yaw(spawned.robot.root_pose().orientation) - heading0, 2 * math.pi)
    return sum(forward_speeds) / len(forward_speeds), turned / (sim.sim_time - start)


def plugin_of(spawned, plugin_class):
    """The spawned model's plugin of exactly ``plugin_class`` (the first one)."""
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


@functools.lru_cache(maxsize=None)
def expanded(path: str, **arguments: str) -> str:
    """expand_xacro's URDF, made once per test process for each file and arguments: the tests expand the same few
    xacros hundreds of times, at a tenth of a second each, and a URDF's text is never changed in place."""
    return expand_xacro(path, **arguments)


def course_urdf(name: str, **arguments: str) -> str:
    """A Gazebo xacro of the course's mbot_description ("mbot_with_kinect_gazebo") as robot_description holds it;
    ``arguments`` are its xacro:arg values."""
    return expanded(os.path.join(WORKSPACE_SRC, "mbot_description", "urdf", "gazebo", name + ".xacro"), **arguments)


def with_imu(urdf: str, accel_noise: bool = False) -> str:
    return urdf.replace("</robot>", IMU_ADDITIONS.format(noise=ACCEL_NOISE if accel_noise else "") + "</robot>")
