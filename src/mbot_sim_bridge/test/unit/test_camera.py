"""core/cameras/camera.py against known geometry: K and P as Gazebo computes them, a coloured box where K says, a wall
at a known distance in the depth image and the cloud, lazy frames and the renderers' agreement."""
import math
import os

import numpy as np
import pybullet
import pytest

from mbot_sim_bridge.core.cameras.camera import Camera, DepthCamera, Intrinsics, camera_intrinsics
from mbot_sim_bridge.core.cameras.render_scene import CameraConfig
from mbot_sim_bridge.core.cameras.image_formats import (convert_image, depth_16uc1, depth_in_range, image_encoding,
                                                        linear_depth, point_cloud)
from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy, rotation_matrix
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world

from sensor_fixtures import box, course_urdf, plugin_of, world_simulation


@pytest.fixture(scope="module")
def kinect_urdf():
    return course_urdf("mbot_with_kinect_gazebo")


@pytest.fixture(scope="module")
def camera_urdf():
    return course_urdf("mbot_with_camera_gazebo")


def test_intrinsics_of_the_course_camera_and_kinect_match_gazebo():
    camera = camera_intrinsics(CameraConfig("c", "l", 1280, 720, 1.3962634), {"hackBaseline": 0.07})
    kinect = camera_intrinsics(CameraConfig("k", "l", 640, 480, math.radians(60)), {})
    print(f"figure: course camera f = {camera.f:.2f} c = ({camera.cx}, {camera.cy}); "
          f"kinect f = {kinect.f:.2f} c = ({kinect.cx}, {kinect.cy})")
    assert camera.f == pytest.approx(762.72, abs=0.01) and (camera.cx, camera.cy) == (640.5, 360.5)
    assert kinect.f == pytest.approx(554.26, abs=0.01) and (kinect.cx, kinect.cy) == (320.5, 240.5)
    assert camera.K == (camera.f, 0, 640.5, 0, camera.f, 360.5, 0, 0, 1)
    assert camera.P[3] == pytest.approx(-camera.f * 0.07) and camera.P[10] == 1.0
    assert Intrinsics.distortion_model == "plumb_bob"


def test_formats_map_to_gazebo_encodings_and_unknown_is_bgr8():
    assert image_encoding("R8G8B8") == ("rgb8", 3, True)
    assert image_encoding("L8") == ("mono8", 1, True)
    assert image_encoding("BAYER_RGGB8") == ("bayer_rggb8", 1, True)
    assert image_encoding("RGB8B8") == ("bgr8", 3, False)
    rgb = np.array([[[10, 20, 30], [40, 50, 60]], [[70, 80, 90], [100, 110, 120]]], dtype=np.uint8)
    assert convert_image(rgb, "bgr8")[0, 0].tolist() == [30, 20, 10]
    assert convert_image(rgb, "rgb16")[0, 0].tolist() == [10 * 257, 20 * 257, 30 * 257]
    assert convert_image(rgb, "bayer_rggb8")[..., 0].tolist() == [[10, 50], [80, 120]]
    assert convert_image(rgb, "mono8").shape == (2, 2, 1)


def test_depth_linearisation_ranges_and_16uc1():
    near, far = 0.05, 8.0
    z = np.array([0.5, 1.5, 7.0], dtype=np.float32)
    buffer = (far - far * near / z) / (far - near)  # the OpenGL depth buffer of these z
    depth = linear_depth(np.append(buffer, 1.0), near, far)
    assert depth[:3] == pytest.approx(z, rel=1e-5) and depth[3] == np.inf
    ranged = depth_in_range(depth, 0.4, 5.0)
    assert np.isnan(ranged[2:]).all() and ranged[0] == pytest.approx(0.5, rel=1e-5)
    # The float32 depth buffer gives 0.5 m and 1.5 m back a hair short (0.49999997, 1.4999999): Gazebo's
    # millimetres truncate, so 499 and 1499 (exact depths: test_16uc1_truncates_to_millimetres_and_saturates).
    assert (depth[:2] < np.float32([0.5, 1.5])).all()
    assert depth_16uc1(ranged).tolist() == [499, 1499, 0, 0]


def test_16uc1_truncates_to_millimetres_and_saturates():
    """gazebo_ros_openni_kinect stores depth * 1000 into a uint16 (a C conversion: truncation); 0 is no reading."""
    depth = np.array([0.5, 1.5, 1.2345, 0.0019, np.nan, np.inf, 70.0], dtype=np.float32)
    assert depth_16uc1(depth).tolist() == [500, 1500, 1234, 1, 0, 0, 65535]


def test_point_cloud_layout_and_geometry():
    depth = np.full((3, 4), 2.0, dtype=np.float32)
    depth[0, 0] = np.nan
    rgb = np.zeros((3, 4, 3), dtype=np.uint8)
    rgb[1, 2] = (200, 100, 50)
    data, dense = point_cloud(depth, math.radians(60), rgb)
    points = np.frombuffer(data, dtype=np.float32).reshape(3, 4, 8)
    f = 4 / (2 * math.tan(math.radians(30)))
    assert not dense and np.isnan(points[0, 0, :3]).all()
    assert points[1, 2, :3] == pytest.approx([2 * (2 - 1.5) / f, 2 * (1 - 1.0) / f, 2.0])
    assert np.frombuffer(data, dtype=np.uint8).reshape(3, 4, 32)[1, 2, 16:19].tolist() == [200, 100, 50]


def test_bad_camera_values_are_refused_with_the_tag(kinect_urdf, tmp_path):
    sim = world_simulation(tmp_path)
    try:
        bad = kinect_urdf.replace("<far>8.0</far>", "<far>0.01</far>")
        with pytest.raises(ConfigError, match="<clip><far>"):
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        bad = kinect_urdf.replace("<width>640</width>", "<width>-3</width>")
        with pytest.raises(ConfigError, match="camera/image/width"):
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        bad = kinect_urdf.replace("<width>640</width>", "<width>8192</width>").replace("<height>480</height>",
                                                                                       "<height>8192</height>")
        with pytest.raises(ConfigError, match=r"<image> 8192 x 8192 is 67,108,864 pixels; a camera renders at most "
                                              r"4,194,304 \(2048 x 2048\) per frame"):
            sim.spawn_robot(parse_robot(bad, "model 'mbot'"), "mbot")
        assert "mbot" not in sim.model_names()
    finally:
        sim.close()


def _optical_point(camera_pose, point):
    """A world point in the camera's optical frame (z forward, x right, y down)."""
    rotation = np.asarray(rotation_matrix(camera_pose.orientation))
    local = rotation.T @ (np.asarray(point) - np.asarray(camera_pose.position))
    return np.array([-local[1], -local[2], local[0]])


def test_a_red_box_appears_where_camera_info_predicts(camera_urdf, tmp_path):
    centre = (2.5, 0.4, 0.3)  # a thin red plate facing the camera, so only its front face shows
    sim = world_simulation(tmp_path, box("red_box", centre, (0.01, 0.12, 0.12), (1, 0, 0)))
    try:
        spawned = sim.spawn_robot(parse_robot(camera_urdf, "model 'mbot'"), "mbot")
        camera = plugin_of(spawned, Camera)
        sim.step(200)
        frame = camera.capture(sim.sim_time)
        image = frame.image
        red = (image[..., 0] > 150) & (image[..., 1] < 80) & (image[..., 2] < 80)
        rows, cols = np.nonzero(red)
        # The plate's near face is what the camera sees; its centre is what K projects.
        pose = camera.sensor_pose()
        x, y, z = _optical_point(pose, (centre[0] - 0.005, centre[1], centre[2]))
        k = camera.intrinsics
        predicted = (k.f * x / z + k.cx, k.f * y / z + k.cy)
        seen = (cols.mean(), rows.mean())
        error = math.hypot(seen[0] - predicted[0], seen[1] - predicted[1])
        print(f"figure: red box centre predicted by K at ({predicted[0]:.1f}, {predicted[1]:.1f}) px, seen at "
              f"({seen[0]:.1f}, {seen[1]:.1f}) px: {error:.2f} px apart ({red.sum()} red pixels, "
              f"{camera.renderer.renderer} renderer)")
        assert red.sum() > 50
        assert error < 2.0
        assert camera.encoding == "rgb8" and image.shape == (720, 1280, 3)
    finally:
        sim.close()


def test_a_wall_at_1_5_m_in_the_depth_image_and_the_cloud(kinect_urdf, tmp_path):
    sim = world_simulation(tmp_path)
    try:
        spawned = sim.spawn_robot(parse_robot(kinect_urdf, "model 'mbot'"), "mbot")
        kinect = plugin_of(spawned, DepthCamera)
        sim.step(100)
        optical = spawned.robot.link_world_pose("kinect_frame_optical")  # frameName, as TF would give it
        # Before the wall: the sky and the floor beyond pointCloudCutoffMax (5 m) are NaN, the near floor is not.
        open_frame = kinect.capture(sim.sim_time)
        open_depth = kinect.depth_image(open_frame)
        beyond = np.isfinite(open_frame.depth) & (open_frame.depth >= 5.0)
        assert np.isnan(open_depth[0]).all() and beyond.any() and np.isnan(open_depth[beyond]).all()
        assert 0.4 < np.nanmin(open_depth) and np.nanmax(open_depth) < 5.0
        wall_x = optical.position[0] + 1.5
        sim.add_world(world_simulation_description(tmp_path, box("wall", (wall_x + 0.05, 0, 1.0), (0.1, 4, 2))))
        frame = kinect.capture(sim.sim_time)
        depth = kinect.depth_image(frame)
        height, width = depth.shape
        centre = depth[height // 2 - 20:height // 2 + 20, width // 2 - 20:width // 2 + 20]
        data, _ = kinect.cloud_data(frame)
        points = np.frombuffer(data, dtype=np.float32).reshape(height, width, 8)[..., :3].reshape(-1, 3)
        points = points[np.isfinite(points).all(axis=1)]
        rotation = np.asarray(rotation_matrix(optical.orientation))
        world = points @ rotation.T + np.asarray(optical.position)
        on_wall = world[(np.abs(world[:, 0] - wall_x) < 0.1) & (world[:, 2] > 0.02)]  # not the floor
        worst = np.abs(on_wall[:, 0] - wall_x).max()
        print(f"figure: wall at 1.5 m reads {np.nanmin(centre):.4f}..{np.nanmax(centre):.4f} m over the image "
              f"centre; {len(on_wall)} cloud points on it lie within {worst * 1000:.2f} mm of the wall plane "
              f"in the world (frame kinect_frame_optical)")
        assert np.nanmax(np.abs(centre - 1.5)) < 0.01
        assert worst < 0.01
        assert len(on_wall) > 0.3 * height * width
        assert np.abs(on_wall[:, 1]).max() < 2.0 and on_wall[:, 2].max() < 2.0  # within the wall's extent
    finally:
        sim.close()


def world_simulation_description(tmp_path, *models):
    """A WorldDescription holding ``models`` (spawn_sdf_model's way of adding them)."""
    path = os.path.join(str(tmp_path), "added.world")
    with open(path, "w") as world:
        world.write(f"<?xml version='1.0'?><sdf version='1.6'><world name='w'>{''.join(models)}</world></sdf>")
    return parse_world(path)


def test_frames_follow_the_sensor_rate_and_the_depth_plugin_renders_once_per_frame(kinect_urdf, tmp_path):
    sim = world_simulation(tmp_path)
    try:
        spawned = sim.spawn_robot(parse_robot(kinect_urdf, "model 'mbot'"), "mbot")
        kinect = plugin_of(spawned, DepthCamera)
        renders = []
        original = kinect.renderer.render
        kinect.renderer.render = lambda pose: renders.append(pose) or original(pose)
        sim.step(1000)
        assert kinect.frame_rate == 20.0
        assert len(renders) == 20  # one render a frame gives the image, the depth and the cloud
        assert kinect.latest.depth is not None and kinect.latest.stamp == pytest.approx(1.0)
    finally:
        sim.close()


def test_both_renderers_put_a_plate_where_camera_info_says_and_egl_misses_earlier_bodies(monkeypatch):
    """TinyRenderer (the default) and PyBullet's EGL renderer both draw a plate within a pixel of where K projects
    it (measured at 640x480: +0.28, -0.15 px for both; at 320x240 EGL is a row lower, +0.43 px; at 1280x720 it
    is +0.05, -0.30 px against TinyRenderer's +0.55, -0.30). The EGL plugin draws no body made before it loaded
    (the render scene gives world models a twin for it), in every client it is loaded into: two in turn here,
    as the bench makes them."""
    from mbot_sim_bridge.core.cameras.render_scene import CameraRenderer
    config = CameraConfig("c", "l", 640, 480, math.radians(60), near=0.05, far=8.0)
    k = camera_intrinsics(config, {})
    later, earlier = (2.0, 0.6, 0.9), (2.0, -0.6, 0.9)  # seen from (0, 0, 0.5) looking along +x: left, right
    predicted = (k.f * -later[1] / 2.0 + k.cx - 1, k.f * -(later[2] - 0.5) / 2.0 + k.cy - 1)  # 0-based
    plate_pixels = 28 * 28  # 0.1 m square at 2 m: 27.7 px a side (f = 554.3 px)
    for renderer in ("tiny", "egl", "egl"):
        monkeypatch.setenv("MBOT_CAMERA_RENDERER", renderer)
        client = pybullet_client()
        try:
            def plate(centre):
                visual = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=[0.001, 0.05, 0.05],
                                                  rgbaColor=[0, 0, 1, 1])
                client.createMultiBody(0, -1, visual, centre)
            plate(earlier)
            camera = CameraRenderer(client, config)
            plate(later)
            assert camera.renderer == renderer
            _, depth = camera.render(pose_from_xyz_rpy((0, 0, 0.5), (0, 0, 0)))
        finally:
            client.disconnect()
        rows, cols = np.nonzero(np.isfinite(depth))
        left = cols < k.cx
        du, dv = cols[left].mean() - predicted[0], rows[left].mean() - predicted[1]
        print(f"figure: {renderer} renderer: plate centre {du:+.2f}, {dv:+.2f} px from the 0-based K projection, "
              f"depth {np.nanmin(depth[:, :int(k.cx)]):.4f} m (true 1.999); the plate made before it "
              f"{np.count_nonzero(~left)} px")
        assert np.count_nonzero(left) == plate_pixels
        assert abs(du) < 1.0 and abs(dv) < 1.0
        assert np.nanmin(depth[:, :int(k.cx)]) == pytest.approx(1.999, abs=0.001)
        assert np.count_nonzero(~left) == (plate_pixels if renderer == "tiny" else 0)


def pybullet_client():
    from pybullet_utils.bullet_client import BulletClient
    return BulletClient(connection_mode=pybullet.DIRECT)
