"""libgazebo_ros_block_laser.so (core/sensors/block_laser.py): a block laser's points land on a wall at a known place,
laid out and placed exactly as upstream's loops place them (mid-angles included); nothing nearer than range_min
is seen; misses sit at range_max without position noise; noise is seeded."""
import math

import numpy as np
import pytest
from sensor_fixtures import box, plugin_of, world_simulation

from mbot_sim_bridge.core.sensors.block_laser import BlockLaser
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.core.description.robot_model import parse_robot

WALL_X = 2.0
SENSOR_Z = 0.6
SAMPLES, H_MIN, H_MAX = 40, -0.4, 0.4
LAYERS, V_MIN, V_MAX = 8, -0.15, 0.15
RANGE_MIN, RANGE_MAX = 0.3, 8.0
STAND = """<robot name="stand">
  <link name="base_link">
    <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.25"/><geometry><box size="0.3 0.3 0.5"/></geometry></collision>
  </link>
  <link name="laser_link"/>
  <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser_link"/>
    <origin xyz="0 0 {z}"/></joint>
  <gazebo reference="laser_link">
    <sensor type="ray" name="block">
      <update_rate>10</update_rate>
      <ray>
        <scan>
          <horizontal><samples>{samples}</samples><resolution>{resolution}</resolution>
            <min_angle>{h_min}</min_angle><max_angle>{h_max}</max_angle></horizontal>
          <vertical><samples>{layers}</samples><resolution>1</resolution>
            <min_angle>{v_min}</min_angle><max_angle>{v_max}</max_angle></vertical>
        </scan>
        <range><min>{range_min}</min><max>{range_max}</max></range>
      </ray>
      <plugin name="block_laser" filename="libgazebo_ros_block_laser.so">
        <topicName>block_cloud</topicName>
        <frameName>laser_link</frameName>
        <gaussianNoise>{noise}</gaussianNoise>
      </plugin>
    </sensor>
  </gazebo>
</robot>"""


def block_laser(tmp_path, *models, noise=0.0, resolution=1, seed=0):
    sim = world_simulation(tmp_path, *models, seed=seed)
    urdf = STAND.format(z=SENSOR_Z, samples=SAMPLES, resolution=resolution, h_min=H_MIN, h_max=H_MAX, layers=LAYERS,
                        v_min=V_MIN, v_max=V_MAX, range_min=RANGE_MIN, range_max=RANGE_MAX, noise=noise)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'stand'"), "stand", Pose((0.0, 0.0, 0.0), (0, 0, 0, 1)))
    sim.step(10)
    return sim, plugin_of(spawned, BlockLaser)


def wall():
    return box("wall", (WALL_X + 0.05, 0.0, 1.0), (0.1, 20.0, 2.0))


def upstream_points(raw, range_count, vertical_range_count):
    """gazebo_ros_block_laser.cpp's PutLaserData, loop by loop, on the raw ranges ``raw[j][i]``."""
    points = []
    for j in range(vertical_range_count):
        vb = 0 if vertical_range_count == 1 else j * (LAYERS - 1) / (vertical_range_count - 1)
        vja = math.floor(vb)
        vjb = min(vja + 1, LAYERS - 1)
        vb -= math.floor(vb)
        for i in range(range_count):
            hb = 0 if range_count == 1 else i * (SAMPLES - 1) / (range_count - 1)
            hja = math.floor(hb)
            hjb = min(hja + 1, SAMPLES - 1)
            hb -= math.floor(hb)
            r = ((1 - vb) * ((1 - hb) * raw[vja][hja] + hb * raw[vja][hjb])
                 + vb * ((1 - hb) * raw[vjb][hja] + hb * raw[vjb][hjb]))
            y_angle = 0.5 * (hja + hjb) * (H_MAX - H_MIN) / (SAMPLES - 1) + H_MIN
            p_angle = 0.5 * (vja + vjb) * (V_MAX - V_MIN) / (LAYERS - 1) + V_MIN
            points.append((r * math.cos(p_angle) * math.cos(y_angle), r * math.cos(p_angle) * math.sin(y_angle),
                           r * math.sin(p_angle)))
    return np.array(points)


def analytic_raw():
    """Each ray's distance to the wall's face at x = WALL_X: raw range = range_min + hit distance = the distance."""
    yaw = np.linspace(H_MIN, H_MAX, SAMPLES)
    pitch = np.linspace(V_MIN, V_MAX, LAYERS)
    return WALL_X / (np.cos(pitch)[:, np.newaxis] * np.cos(yaw)[np.newaxis, :])


@pytest.mark.parametrize("resolution", [1, 2])
def test_points_are_placed_as_upstream_places_them(tmp_path, resolution):
    sim, laser = block_laser(tmp_path, wall(), resolution=resolution)
    cloud = laser.cloud()
    expected = upstream_points(analytic_raw(), SAMPLES * resolution, LAYERS)
    assert cloud.xyz.shape == (SAMPLES * resolution * LAYERS, 3)
    assert cloud.xyz == pytest.approx(expected, abs=1e-3)
    assert not cloud.intensity.any()  # retro 0, no noise
    sim.close()


def test_every_layer_sees_the_wall_within_2_cm(tmp_path):
    sim, laser = block_laser(tmp_path, wall())
    xyz = laser.cloud().xyz.reshape(LAYERS, SAMPLES, 3)
    worst = np.abs(xyz[..., 0] - WALL_X).max(axis=1)
    print(f"figure: block laser, wall {WALL_X} m ahead: {LAYERS} layers of {SAMPLES}, worst |x - wall| per layer "
          f"{', '.join(f'{value * 100:.2f}' for value in worst)} cm (points at upstream's mid-angles)")
    assert (worst < 0.02).all()
    sim.close()


def test_nothing_nearer_than_range_min_and_misses_at_range_max_without_noise(tmp_path):
    post = box("post", (RANGE_MIN / 2, 0.0, SENSOR_Z), (0.05, 0.05, 0.4))  # inside range_min, straight ahead
    sim, laser = block_laser(tmp_path, post, noise=0.01)
    cloud = laser.cloud()
    distances = np.linalg.norm(cloud.xyz, axis=1)
    # Nothing but the ground below the sensor: the upper rays miss and read range_max exactly (no noise added).
    upper = cloud.xyz.reshape(LAYERS, SAMPLES, 3)[LAYERS // 2:].reshape(-1, 3)
    directions = upper / np.linalg.norm(upper, axis=1)[:, np.newaxis]
    assert np.linalg.norm(upper, axis=1) == pytest.approx(RANGE_MAX, abs=1e-4)
    assert (directions[:, 2] > 0).all()
    assert distances.min() > 2.0  # the post is not seen, the lower rays reach the ground
    sim.close()


def test_noise_is_seeded(tmp_path):
    clouds = []
    for run in range(2):
        (tmp_path / str(run)).mkdir()
        sim, laser = block_laser(tmp_path / str(run), wall(), noise=0.01, seed=3)
        clouds.append(laser.cloud())
        sim.close()
    assert np.array_equal(clouds[0].xyz, clouds[1].xyz)
    spread = clouds[0].xyz[:, 0] - upstream_points(analytic_raw(), SAMPLES, LAYERS)[:, 0]
    assert 0.005 < spread.std() < 0.02
    assert 0.005 < clouds[0].intensity.std() < 0.02
