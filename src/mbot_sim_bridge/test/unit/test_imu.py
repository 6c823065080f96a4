"""core/sensors/imu.py and core/sensors/p3d.py on the course's mbot with an IMU board on a fixed joint (lumped, as
TurtleBot3's imu_link): at rest, turning at 0.5 rad/s, and against the world pose."""
import logging

import numpy as np
import pytest

from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import Pose, compose, pose_from_xyz_rpy, rotation_matrix, yaw
from mbot_sim_bridge.core.sensors.imu import ImuModelPlugin, ImuSensor
from mbot_sim_bridge.core.sensors.p3d import P3D
from mbot_sim_bridge.core.description.robot_model import parse_robot

from sensor_fixtures import course_urdf, plugin_of, with_imu, world_simulation

ACCEL_SIGMA = 0.017


@pytest.fixture(scope="module")
def mbot_urdf():
    return course_urdf("mbot_gazebo")


def spawn(tmp_path, urdf, yaw_angle=0.7):
    sim = world_simulation(tmp_path)
    pose = pose_from_xyz_rpy((0.5, -0.2, 0.0), (0, 0, yaw_angle))
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'mbot'"), "mbot", pose)
    return sim, spawned


def test_imu_sensor_at_rest_reads_gravity_up_and_the_true_yaw(mbot_urdf, tmp_path):
    sim, spawned = spawn(tmp_path, with_imu(mbot_urdf, accel_noise=True))
    try:
        sensor = plugin_of(spawned, ImuSensor)
        assert sensor.timer.period == pytest.approx(0.01)  # min(<update_rate> 200, updateRateHZ 100)
        sim.step(1500)
        readings = []
        for _ in range(50):
            sim.step(10)
            readings.append(sensor.latest)
        accel_z = np.array([reading.linear_acceleration[2] for reading in readings])
        gravity = abs(sim.engine.physics.gravity[2])
        truth = yaw(spawned.robot.root_pose().orientation)
        yaw_error = abs(yaw(readings[-1].orientation) - truth)
        print(f"figure: imu sensor at rest: linear_acceleration.z mean {accel_z.mean():.4f} m/s^2, std "
              f"{accel_z.std():.4f} (noise sigma {ACCEL_SIGMA}; world gravity {gravity}); yaw error "
              f"{yaw_error:.2e} rad")
        assert abs(accel_z.mean() - 9.81) < 3 * ACCEL_SIGMA
        assert np.all(np.abs(accel_z - gravity) < 5 * ACCEL_SIGMA)
        assert accel_z.std() == pytest.approx(ACCEL_SIGMA, rel=0.5)
        assert yaw_error < 0.01
        assert readings[-1].covariance == 0.0
    finally:
        sim.close()


def test_turning_at_half_a_radian_per_second(mbot_urdf, tmp_path):
    sim, spawned = spawn(tmp_path, with_imu(mbot_urdf))
    try:
        sensor, model_imu = plugin_of(spawned, ImuSensor), plugin_of(spawned, ImuModelPlugin)
        plugin_of(spawned, DiffDrive).set_command(0.0, 0.5)
        sim.step(3000)
        rates = []
        for _ in range(20):
            sim.step(10)
            rates.append((sensor.latest.angular_velocity[2], model_imu.latest.angular_velocity[2]))
        sensor_rate, model_rate = np.mean(rates, axis=0)
        true_rate = spawned.robot.link_world_velocity("base_link")[1][2]
        print(f"figure: turning at 0.5 rad/s: imu sensor angular_velocity.z {sensor_rate:.4f}, libgazebo_ros_imu "
              f"{model_rate:.4f}, true {true_rate:.4f} rad/s")
        assert sensor_rate == pytest.approx(0.5, rel=0.02)
        assert model_rate == pytest.approx(0.5, rel=0.02)
        assert sensor_rate == pytest.approx(true_rate, rel=0.005)
    finally:
        sim.close()


def test_model_imu_is_gazebo_s_lumped_body_without_gravity(mbot_urdf, tmp_path):
    sim, spawned = spawn(tmp_path, with_imu(mbot_urdf))
    try:
        imu = plugin_of(spawned, ImuModelPlugin)
        # sdformat renames a lumped bodyName/frameName to the surviving link, as TurtleBot3's /imu shows.
        assert imu.link == "base_footprint" and imu.frame_name == "base_footprint"
        sim.step(1500)
        reading = imu.latest
        yaw_error = abs(yaw(reading.orientation) - yaw(spawned.robot.root_pose().orientation))
        print(f"figure: libgazebo_ros_imu at rest: linear_acceleration {np.round(reading.linear_acceleration, 4)} "
              f"(Gazebo leaves gravity out of this plugin), yaw error {yaw_error:.2e} rad")
        assert np.abs(reading.linear_acceleration).max() < 0.05
        assert yaw_error < 0.01
    finally:
        sim.close()


def every_step_imu(urdf: str, body: str) -> str:
    return (with_imu(urdf).replace("<updateRate>100</updateRate>", "<updateRate>0</updateRate>")
            .replace("<bodyName>imu_link</bodyName>", f"<bodyName>{body}</bodyName><rpyOffset>0.1 0 0.3</rpyOffset>"))


@pytest.mark.parametrize("body", ["imu_link", "left_wheel_link"])
def test_every_step_imu_reads_each_step_without_stopping_the_loop(mbot_urdf, tmp_path, body):
    """updateRate 0: the body is recorded after every step and the readings computed when the loop stops; each
    equals what the pose and velocity at its own step give (checked one step at a time in a twin simulation)."""
    batched, single = (spawn(tmp_path, every_step_imu(mbot_urdf, body)) for _ in range(2))
    try:
        batches = []
        for sim, spawned in (batched, single):
            plugin_of(spawned, DiffDrive).set_command(0.3, 0.8)
        imu = plugin_of(batched[1], ImuModelPlugin)
        update = imu.update
        imu.update = lambda now: (update(now), batches.append(imu.readings))
        batched[0].step(300)
        sim, spawned = single
        reference = plugin_of(spawned, ImuModelPlugin)
        robot, step, expected = spawned.robot, sim.step_size, []
        velocity = np.asarray(robot.link_world_velocity(reference.link)[0])
        for _ in range(300):
            sim.step(1)
            orientation = compose(Pose((0, 0, 0), reference.offset), robot.link_world_pose(reference.link)).orientation
            rotation = np.asarray(rotation_matrix(orientation))
            linear, angular = (np.asarray(vector) for vector in robot.link_world_velocity(reference.link))
            expected.append(np.concatenate((orientation, rotation @ angular, rotation @ ((linear - velocity) / step))))
            velocity = linear
        readings = np.vstack([np.hstack((b.orientations, b.angular_velocities, b.linear_accelerations))
                              for b in batches])
        stamps = np.concatenate([b.stamps for b in batches])
        sizes = [len(b.stamps) for b in batches]
        expected = np.asarray(expected)
        print(f"figure: every-step IMU on {imu.link}: 300 steps read in {len(batches)} stops of the loop (largest "
              f"{max(sizes)} steps); largest difference from the one-step reference "
              f"{np.abs(readings - expected).max():.1e}")
        # The mbot's other plugins stop the loop about every 5 steps; without recording it stopped at each.
        assert len(batches) <= 300 // 4 and max(sizes) >= 5
        assert np.allclose(np.diff(stamps), step) and stamps[-1] == pytest.approx(sim.sim_time)
        # PyBullet's transform helpers (the reference) work in single precision: about 1e-7 of a quaternion and
        # of a rate (a wheel turns at 15 rad/s), which Δv/Δt over a 1 ms step turns into up to 1e-4 m/s².
        assert np.allclose(readings[:, :7], expected[:, :7], rtol=0, atol=1e-5)
        assert np.allclose(readings[:, 7:], expected[:, 7:], atol=2e-4)
        assert np.abs(expected[:, 4:7]).max() > 0.5  # the body turns: the check is not of zeros
    finally:
        batched[0].close()
        single[0].close()


def test_every_step_imu_is_read_again_soon_after_reset_simulation(mbot_urdf, tmp_path):
    """Read, unread, read, as the ROS layer calls it while /imu is subscribed or not, across reset_simulation
    (sim time back to 0): once read again, the readings start within IDLE_PERIOD."""
    sim, spawned = spawn(tmp_path, every_step_imu(mbot_urdf, "imu_link"))
    try:
        imu = plugin_of(spawned, ImuModelPlugin)
        listened = [False]
        update = imu.update
        imu.update = lambda now: update(now) if listened[0] else imu.idle(now)
        for read, steps in ((False, 2000), (True, 100), ("reset", 0), (False, 10), (True, 100)):
            if read == "reset":
                sim.reset(True)
            else:
                listened[0] = read
                sim.step(steps)
        assert sim.sim_time == pytest.approx(0.11)
        assert imu.readings.stamps[-1] == pytest.approx(sim.sim_time)
        assert len(imu.readings.stamps) < 20  # recording again, in batches
    finally:
        sim.close()


def test_p3d_equals_the_world_pose(mbot_urdf, tmp_path):
    sim, spawned = spawn(tmp_path, with_imu(mbot_urdf))
    try:
        p3d = plugin_of(spawned, P3D)
        plugin_of(spawned, DiffDrive).set_command(0.3, 0.4)
        sim.step(2000)
        truth = p3d.read(sim.sim_time)
        pose = spawned.robot.link_world_pose("base_link")
        velocity = spawned.robot.link_world_velocity("base_link")
        position_error = max(abs(a - b) for a, b in zip(truth.pose.position, pose.position))
        q, r = np.asarray(truth.pose.orientation), np.asarray(pose.orientation)
        angle_error = min(np.abs(q - r).max(), np.abs(q + r).max())  # quaternion components
        print(f"figure: p3d vs world pose: position error {position_error:.2e} m, quaternion {angle_error:.2e}; "
              f"frame '{p3d.frame_name}', child '{p3d.child_frame}'")
        assert position_error < 1e-9 and angle_error < 1e-9
        assert truth.linear == pytest.approx(velocity[0]) and truth.angular == pytest.approx(velocity[1])
        assert (p3d.frame_name, p3d.child_frame) == ("world", "base_footprint")
    finally:
        sim.close()


def test_bad_imu_and_p3d_tags_are_refused_with_the_tag(mbot_urdf, tmp_path):
    sim = world_simulation(tmp_path)
    try:
        bad = with_imu(mbot_urdf).replace("<bodyName>imu_link</bodyName>", "<bodyName>nowhere</bodyName>")
        with pytest.raises(ConfigError, match="bodyName: nowhere does not exist"):
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        bad = with_imu(mbot_urdf).replace("<frameName>imu_link</frameName>\n                <updateRateHZ>",
                                          "<updateRateHZ>")
        with pytest.raises(ConfigError, match="frameName"):
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        bad = with_imu(mbot_urdf).replace("<updateRate>50</updateRate>", "<updateRate>-1</updateRate>")
        with pytest.raises(ConfigError, match="updateRate"):
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        # A noise whose variance (the covariance diagonals) overflows a float is refused, for each plugin.
        for plugin in ("imu_plugin", "imu_sensor", "ground_truth"):
            start = with_imu(mbot_urdf).index(f'<plugin name="{plugin}"')
            bad = with_imu(mbot_urdf)
            end = bad.index("</plugin>", start)
            block = bad[start:end]
            noisy = (block.replace("<gaussianNoise>0.0</gaussianNoise>", "<gaussianNoise>1e308</gaussianNoise>")
                     if "gaussianNoise" in block else block + "<gaussianNoise>1e308</gaussianNoise>")
            with pytest.raises(ConfigError, match="gaussianNoise.*1e308"):
                sim.spawn_robot(parse_robot(bad[:start] + noisy + bad[end:], "model 'mbot'"), "mbot")
        assert "mbot" not in sim.model_names()
    finally:
        sim.close()


def test_an_unknown_sensor_warns_once_and_the_rest_works(mbot_urdf, tmp_path, caplog):
    prosilica = """<gazebo reference="base_link"><sensor type="camera" name="prosilica"><update_rate>10</update_rate>
        <plugin name="prosilica" filename="libgazebo_ros_prosilica.so"><cameraName>prosilica</cameraName></plugin>
        </sensor></gazebo></robot>"""
    sim = world_simulation(tmp_path)
    try:
        urdf = with_imu(mbot_urdf).replace("</robot>", prosilica)
        spawned = sim.spawn_robot(parse_robot(urdf, "model 'mbot'"), "mbot")
        sim.step(100)
        warnings = [message for message in map(logging.LogRecord.getMessage, caplog.records)
                    if "libgazebo_ros_prosilica.so" in message]
        assert len(warnings) == 1 and "not emulated" in warnings[0]
        assert plugin_of(spawned, ImuSensor).latest is not None and plugin_of(spawned, P3D).latest is not None
    finally:
        sim.close()
