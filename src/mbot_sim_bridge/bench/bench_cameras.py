#!/usr/bin/env python3
"""Camera and IMU cost figures, printed one per line (part of ``./mbot bench``).

(a) per camera size (320x240, 640x480, 1280x720) and renderer (TinyRenderer, the default; PyBullet's EGL
    plugin on the platform's GL): the wall time of one frame of the course's kinect in the play ground
    (render + depth linearisation + rgb8), and of the depth image and point cloud built from it;
(b) the real-time factor of the course's camera robot (1280x720 at 30 Hz) and kinect robot (640x480 at
    20 Hz) in the play ground with the image subscribed, each frame serialized as the ROS message;
(c) the real-time factor of the mbot with TurtleBot3's IMU plugin at updateRate 0 (a reading for every 1 ms
    step, serialized as the bridge does) against the same robot without it: the medians of seven pairs.

The machine's load changes these figures (--runs N takes the median of N runs for (b)). ``--short`` renders
every image at a quarter of its width and height, over tiny durations.

    PYTHONPATH=src/mbot_sim_bridge/src .venv/bin/python src/mbot_sim_bridge/bench/bench_cameras.py
"""
import argparse
import io
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(WORKSPACE, "src", "mbot_sim_bridge", "src"))

from sensor_msgs.msg import Image  # noqa: E402 (after the path set-up)
from results import parse_arguments, report  # noqa: E402

from mbot_sim_bridge.core.cameras.camera import Camera, DepthCamera  # noqa: E402
from mbot_sim_bridge.core.drives.diff_drive import DiffDrive  # noqa: E402
from mbot_sim_bridge.core.sensors.imu import ImuModelPlugin  # noqa: E402
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS  # noqa: E402
from mbot_sim_bridge.core.cameras.render_scene import RENDERER_ENV  # noqa: E402
from mbot_sim_bridge.core.description.robot_model import parse_robot  # noqa: E402
from mbot_sim_bridge.core.description.sdf_world import parse_world  # noqa: E402
from mbot_sim_bridge.core.simulation import Simulation  # noqa: E402
from mbot_sim_bridge.plugins.messages import imu_records  # noqa: E402
from mbot_sim_bridge.robot_description import expand_xacro  # noqa: E402

PLAY_GROUND = os.path.join(WORKSPACE, "src", "mbot_gazebo", "worlds", "playground.world")
SIZES = ((320, 240), (640, 480), (1280, 720))
KINECT_SIZE, CAMERA_SIZE = (640, 480), (1280, 720)  # the course's xacros'
SHORT_SCALE = 4  # --short divides every image's width and height by this
IMU_PAIRS = 7
# TurtleBot3 burger's IMU plugin block (turtlebot3_burger.gazebo.xacro), on a board lumped into the base.
IMU_BLOCK = """<link name="imu_link"/>
<joint name="imu_joint" type="fixed"><origin xyz="-0.03 0 0.07"/><parent link="base_link"/><child link="imu_link"/>
</joint>
<gazebo><plugin name="imu_plugin" filename="libgazebo_ros_imu.so"><alwaysOn>true</alwaysOn>
<bodyName>imu_link</bodyName><frameName>imu_link</frameName><topicName>imu</topicName>
<serviceName>imu_service</serviceName><gaussianNoise>0.0</gaussianNoise><updateRate>0</updateRate></plugin></gazebo>
</robot>"""


def course_urdf(name: str) -> str:
    package_path = os.environ.get("ROS_PACKAGE_PATH", "")
    os.environ["ROS_PACKAGE_PATH"] = os.path.join(WORKSPACE, "src") + os.pathsep + package_path
    path = os.path.join(WORKSPACE, "src", "mbot_description", "urdf", "gazebo", name + ".xacro")
    return expand_xacro(path)


def spawn(urdf: str):
    sim = Simulation(parse_world(PLAY_GROUND), CORE_PLUGINS)
    spawned = sim.spawn_robot(parse_robot(urdf, "model 'mbot'"), "mbot")
    return sim, spawned


def serialized(message) -> int:
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.tell()


def resized(urdf: str, size, new_size) -> str:
    """The URDF with its camera's image of ``size`` (width, height) made ``new_size``."""
    for tag, old, new in zip(("width", "height"), size, new_size):
        if f"<{tag}>{old}</{tag}>" not in urdf:
            raise ValueError(f"the camera's <{tag}> is not {old}: the course's xacro changed")
        urdf = urdf.replace(f"<{tag}>{old}</{tag}>", f"<{tag}>{new}</{tag}>")
    return urdf


def frame_costs(kinect_urdf: str, width: int, height: int, frames: int):
    """Median ms of: one frame (render, rgb8), the depth image, the point cloud."""
    sim, spawned = spawn(resized(kinect_urdf, KINECT_SIZE, (width, height)))
    try:
        kinect = next(plugin for plugin in spawned.plugins if isinstance(plugin, DepthCamera))
        sim.step(100)
        kinect.capture(sim.sim_time)
        render, depth, cloud = [], [], []
        for _ in range(frames):
            start = time.perf_counter()
            frame = kinect.capture(sim.sim_time)
            middle = time.perf_counter()
            kinect.depth_image(frame).tobytes()
            after_depth = time.perf_counter()
            kinect.cloud_data(frame)
            render.append(middle - start)
            depth.append(after_depth - middle)
            cloud.append(time.perf_counter() - after_depth)
        return (1000 * statistics.median(render), 1000 * statistics.median(depth), 1000 * statistics.median(cloud),
                kinect.renderer.renderer)
    finally:
        sim.close()


def camera_rtf(urdf: str, sim_seconds: float) -> float:
    """Real-time factor with every frame's image built and serialized, as a subscribed topic gets it."""
    sim, spawned = spawn(urdf)
    try:
        camera = next(plugin for plugin in spawned.plugins if isinstance(plugin, Camera))
        update = camera.update

        def update_and_serialize(now):
            update(now)
            frame = camera.latest
            image = Image(height=frame.image.shape[0], width=frame.image.shape[1], encoding=camera.encoding,
                          step=frame.image.strides[0], data=frame.image.tobytes())
            serialized(image)

        camera.update = update_and_serialize
        return timed_rtf(sim, sim_seconds)
    finally:
        sim.close()


def imu_rtf(urdf: str, sim_seconds: float, with_imu: bool) -> float:
    sim, spawned = spawn(urdf.replace("</robot>", IMU_BLOCK) if with_imu else urdf)
    try:
        for plugin in spawned.plugins:
            if isinstance(plugin, ImuModelPlugin):
                update = plugin.update

                def update_and_serialize(now, plugin=plugin, update=update):
                    update(now)
                    imu_records(plugin.readings, plugin.frame_name).tobytes()

                plugin.update = update_and_serialize
            if isinstance(plugin, DiffDrive):
                plugin.set_command(0.2, 0.3)
        return timed_rtf(sim, sim_seconds)
    finally:
        sim.close()


def timed_rtf(sim, sim_seconds: float) -> float:
    """Real-time factor over ``sim_seconds``, after 200 steps that let the robot settle."""
    sim.step(200)
    start = time.perf_counter()
    sim.step(int(round(sim_seconds / sim.step_size)))
    return sim_seconds / (time.perf_counter() - start)


def median_of(runs, function, *args):
    return statistics.median(function(*args) for _ in range(runs))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=5, help="frames timed per camera size")
    parser.add_argument("--sim-seconds", type=float, default=2.0, help="sim time of each real-time-factor run")
    parser.add_argument("--runs", type=int, default=1, help="runs per camera real-time factor (median)")
    args = parse_arguments(parser, "images at a quarter of their width and height, one frame, tiny durations")
    if args.short:
        args.frames, args.sim_seconds = 1, 0.1
    scale = SHORT_SCALE if args.short else 1

    def scaled(size):
        return size[0] // scale, size[1] // scale

    kinect_size, camera_size = scaled(KINECT_SIZE), scaled(CAMERA_SIZE)
    kinect_urdf, mbot_urdf = course_urdf("mbot_with_kinect_gazebo"), course_urdf("mbot_gazebo")
    camera_urdf = resized(course_urdf("mbot_with_camera_gazebo"), CAMERA_SIZE, camera_size)
    kinect_rtf_urdf = resized(kinect_urdf, KINECT_SIZE, kinect_size)
    for renderer in ("tiny", "egl"):
        os.environ[RENDERER_ENV] = renderer
        for width, height in map(scaled, SIZES):
            render, depth, cloud, used = frame_costs(kinect_urdf, width, height, args.frames)
            report(f"camera frame {width}x{height}, {renderer} renderer", f"{render:.1f} ms render + rgb8, "
                   f"{depth:.1f} ms depth image, {cloud:.1f} ms point cloud (rendered with {used})")
    for renderer in ("tiny", "egl"):
        os.environ[RENDERER_ENV] = renderer
        report(f"course camera robot real-time factor ({camera_size[0]}x{camera_size[1]} at 30 Hz, image subscribed), "
               f"{renderer} renderer", f"{median_of(args.runs, camera_rtf, camera_urdf, args.sim_seconds):.2f}")
        report(f"course kinect robot real-time factor ({kinect_size[0]}x{kinect_size[1]} at 20 Hz, rgb image "
               f"subscribed), {renderer} renderer",
               f"{median_of(args.runs, camera_rtf, kinect_rtf_urdf, args.sim_seconds):.2f}")
    os.environ.pop(RENDERER_ENV)
    # A run takes a fraction of a second: pairs measured in turn, so that a slower moment of the machine
    # falls on both sides of a ratio.
    pairs = [(imu_rtf(mbot_urdf, args.sim_seconds, False), imu_rtf(mbot_urdf, args.sim_seconds, True))
             for _ in range(1 if args.short else IMU_PAIRS)]
    without, with_imu = (statistics.median(side) for side in zip(*pairs))
    ratio = statistics.median(with_run / without_run for without_run, with_run in pairs)
    report("mbot real-time factor with TurtleBot3's libgazebo_ros_imu.so at updateRate 0 / without",
           f"{with_imu:.2f} / {without:.2f}; ratio {ratio:.2f} (target >= 0.9; medians of {len(pairs)} pairs)")

if __name__ == "__main__":
    main()
