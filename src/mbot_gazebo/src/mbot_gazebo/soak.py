"""``./mbot soak [minutes]``: the lidar mbot in the play ground at real-time factor 0 under random commands.

Every minute and at the end it prints the bridge's RSS (and its anonymous part), the real-time factor, NaN
counts, stamps going backwards and the deepest overlap of the robot with any world body, and exits non-zero on
any NaN, a backwards stamp, growth of the anonymous memory (the heap, where a leak shows) over 5 % after the
warm-up minute, or a tunnelling.

The overlap is measured in a PyBullet copy of the world held by this process: the same world file and robot
description, with the robot (and every movable world model) put where /gazebo/get_model_state says it is,
about ten times a second. A robot that tunnelled into a wall or fell through the floor shows as a large negative
distance (contact depth; for static meshes, which Bullet sees as hollow surfaces, also the depth of the robot's
centre inside the mesh's outline).
"""
import argparse
import math
import os
import random
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client

import numpy
import rosgraph
import rosnode
import rospkg
import rospy
from gazebo_msgs.srv import GetModelState
from geometry_msgs.msg import Twist
from mbot_sim_bridge.core.engine import Engine
from mbot_sim_bridge.core.geometry import Pose
from mbot_sim_bridge.gazebo_paths import model_path
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.world_bodies import load_world
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState, LaserScan
from tf2_msgs.msg import TFMessage

from mbot_sim_bridge.processes import PrivateMaster, stop_process_group

from .footprints import footprint

ROBOT = "mbot"
MEMORY_GROWTH_LIMIT = 0.05
# Deeper than this, the robot is inside an obstacle or the floor (contact penetration stays at a few mm).
TUNNEL_DEPTH = 0.05
WARM_UP_SECONDS = 60.0
COMMAND_PERIOD = 0.5  # wall seconds between new random commands
SAMPLE_PERIOD = 0.1  # wall seconds between overlap measurements
START_TIMEOUT = 120.0


def _finite(*values) -> bool:
    return all(math.isfinite(v) for v in values)


class Watcher:
    """NaN and backwards-stamp counts of everything the simulation publishes about the robot."""

    def __init__(self):
        self.lock = threading.Lock()
        self.nan = {}
        self.backwards = {}
        self.messages = 0
        self.sim_time = None
        self._last = {}
        self.subscribers = [
            rospy.Subscriber("/clock", Clock, self._on_clock, queue_size=10),
            rospy.Subscriber("/odom", Odometry, self._on_odometry, queue_size=10),
            rospy.Subscriber("/scan", LaserScan, self._on_scan, queue_size=10),
            rospy.Subscriber("/joint_states", JointState, self._on_joint_states, queue_size=10),
            rospy.Subscriber("/tf", TFMessage, self._on_tf, queue_size=10),
        ]

    def _stamp(self, message, key, stamp):
        # Per publisher: two nodes on one topic (the bridge and joint_state_publisher) keep clocks of their own.
        key = f"{key} from {message._connection_header['callerid']}"
        seconds = stamp.to_sec()
        if key in self._last and seconds < self._last[key]:
            self.backwards[key] = self.backwards.get(key, 0) + 1
        self._last[key] = seconds

    def _check(self, topic, finite):
        self.messages += 1
        if not finite:
            self.nan[topic] = self.nan.get(topic, 0) + 1

    def _on_clock(self, message):
        with self.lock:
            self._stamp(message, "/clock", message.clock)
            self.sim_time = message.clock.to_sec()
            self._check("/clock", True)

    def _on_odometry(self, message):
        pose, twist = message.pose.pose, message.twist.twist
        with self.lock:
            self._stamp(message, "/odom", message.header.stamp)
            self._check("/odom", _finite(pose.position.x, pose.position.y, pose.position.z, pose.orientation.x,
                                         pose.orientation.y, pose.orientation.z, pose.orientation.w,
                                         twist.linear.x, twist.linear.y, twist.angular.z))

    def _on_scan(self, message):
        with self.lock:
            self._stamp(message, "/scan", message.header.stamp)
            # Out of range reads inf; only NaN is wrong.
            self._check("/scan", not any(math.isnan(r) for r in message.ranges))

    def _on_joint_states(self, message):
        with self.lock:
            self._stamp(message, "/joint_states", message.header.stamp)
            self._check("/joint_states", _finite(*message.position, *message.velocity, *message.effort))

    def _on_tf(self, message):
        with self.lock:
            for transform in message.transforms:
                self._stamp(message, "/tf " + transform.child_frame_id, transform.header.stamp)
                t, q = transform.transform.translation, transform.transform.rotation
                self._check("/tf", _finite(t.x, t.y, t.z, q.x, q.y, q.z, q.w))

    def counts(self):
        with self.lock:
            return sum(self.nan.values()), sum(self.backwards.values()), dict(self.nan), dict(self.backwards)


class OverlapProbe:
    """A PyBullet copy of the world in which the robot is placed where the simulator has it."""

    def __init__(self, world_path: str, robot_xml: str):
        world = parse_world(world_path, model_path())
        self.engine = Engine(world.physics)
        loaded = load_world(self.engine.client, world)
        self.engine.add_world(loaded)
        self.engine.spawn_robot(parse_robot(robot_xml), ROBOT)
        self.world_bodies = dict(loaded.bodies)
        self.movable = [model.name for model in world.models if not model.static and model.name in loaded.bodies]
        # A static mesh is a hollow triangle surface to Bullet: a robot wholly inside one touches no triangle.
        # Its top-view outline and height catch that case.
        self.mesh_footprints = [(model.name, numpy.asarray(footprint(shape)), shape.bounds()[0][2],
                                 shape.bounds()[1][2])
                                for model in world.models if model.static for shape in model.shapes
                                if shape.kind == "mesh"]
        self.deepest = (math.inf, "")

    def measure(self, poses) -> float:
        """Place the models at ``poses`` (name -> Pose); the robot's deepest overlap (m, negative = inside)."""
        for name, pose in poses.items():
            self.engine.set_model_state(name, pose)
        body = self.engine.body_of(ROBOT)
        deepest = (math.inf, "")
        for name, other in self.world_bodies.items():
            for point in self.engine.client.getClosestPoints(body, other, 0.0):
                deepest = min(deepest, (point[8], name))
        x, y, z = poses[ROBOT].position
        for name, outline, bottom, top in self.mesh_footprints:
            if bottom <= z <= top and _inside(outline, (x, y)):
                deepest = min(deepest, (-_distance_to_outline(outline, (x, y)), name))
        self.deepest = min(self.deepest, deepest)
        return deepest[0]


def _inside(outline: numpy.ndarray, point) -> bool:
    """Whether ``point`` lies in the counter-clockwise convex polygon ``outline``."""
    edges = numpy.roll(outline, -1, axis=0) - outline
    to_point = numpy.asarray(point) - outline
    return bool(numpy.all(edges[:, 0] * to_point[:, 1] - edges[:, 1] * to_point[:, 0] >= 0))


def _distance_to_outline(outline: numpy.ndarray, point) -> float:
    starts, ends = outline, numpy.roll(outline, -1, axis=0)
    edges = ends - starts
    along = numpy.clip(numpy.einsum("ij,ij->i", numpy.asarray(point) - starts, edges)
                       / numpy.maximum(numpy.einsum("ij,ij->i", edges, edges), 1e-12), 0.0, 1.0)
    nearest = starts + along[:, None] * edges
    return float(numpy.min(numpy.linalg.norm(nearest - numpy.asarray(point), axis=1)))


def _memory_megabytes(pid: int):
    """(RSS, its anonymous part) in MB. A leak grows the anonymous part; the file-backed rest (libraries)
    shrinks and grows again as the kernel reclaims pages under other processes' memory pressure."""
    values = {}
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "RssAnon"):
                values[key] = int(value.split()[0]) / 1024.0
    return values["VmRSS"], values["RssAnon"]


def _bridge_pid() -> int:
    uri = rosnode.get_api_uri(rosgraph.Master("/mbot_soak"), "/gazebo")
    code, message, pid = xmlrpc.client.ServerProxy(uri).getPid("/mbot_soak")
    if code != 1:
        raise RuntimeError(f"the bridge did not give its pid: {message}")
    return pid


def _pose(response) -> Pose:
    p, q = response.pose.position, response.pose.orientation
    return Pose((p.x, p.y, p.z), (q.x, q.y, q.z, q.w))


def _overlap_text(depth: float, name: str) -> str:
    return "none" if math.isinf(depth) else f"{depth:.4f} m ({name})"


def soak(seconds: float, world_path: str, seed: int, launch_log) -> int:
    rospy.init_node("mbot_soak", disable_signals=True)
    deadline = time.monotonic() + START_TIMEOUT
    get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
    while True:
        try:
            get_state.wait_for_service(1.0)
            if get_state(ROBOT, "").success:
                break
        except (rospy.ROSException, rospy.ServiceException):
            pass
        if time.monotonic() > deadline:
            print(f"mbot soak: the mbot did not appear within {START_TIMEOUT:.0f} s (see {launch_log})",
                  file=sys.stderr)
            return 1
        time.sleep(0.1)
    pid = _bridge_pid()
    watcher = Watcher()
    probe = OverlapProbe(world_path, rospy.get_param("/robot_description"))
    commands = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
    generator = random.Random(seed)
    failures = []

    start = time.monotonic()
    baseline_anonymous = None
    minute_start, minute_sim = start, None
    next_report = start + 60.0
    next_command = start
    samples = 0
    while True:
        now = time.monotonic()
        finished = now - start >= seconds
        if now >= next_command:
            twist = Twist()
            # Beyond the mbot's usual speeds and into the obstacles: contacts and limits get exercised.
            twist.linear.x, twist.angular.z = generator.uniform(-1.0, 1.0), generator.uniform(-3.0, 3.0)
            commands.publish(twist)
            next_command = now + COMMAND_PERIOD
        try:
            poses = {ROBOT: _pose(get_state(ROBOT, ""))}
            poses.update((name, _pose(get_state(name, ""))) for name in probe.movable)
        except rospy.ServiceException as error:
            failures.append(f"get_model_state failed: {error}")
            break
        depth = probe.measure(poses)
        samples += 1
        if depth < -TUNNEL_DEPTH or poses[ROBOT].position[2] < -TUNNEL_DEPTH:
            failures.append(f"the robot tunnelled: overlap {depth:.3f} m at {poses[ROBOT].position}")
            finished = True
        if baseline_anonymous is None and now - start >= min(WARM_UP_SECONDS, seconds / 2):
            baseline_anonymous = _memory_megabytes(pid)[1]
        if now >= next_report or finished:
            rss, anonymous = _memory_megabytes(pid)
            nan, backwards, nan_by_topic, backwards_by_key = watcher.counts()
            with watcher.lock:
                sim_now = watcher.sim_time or 0.0
            rtf = (sim_now - (minute_sim if minute_sim is not None else 0.0)) / max(now - minute_start, 1e-9)
            print(f"soak: {(now - start) / 60.0:5.1f} min | RSS {rss:.1f} MB (anonymous {anonymous:.1f} MB) | RTF "
                  f"{rtf:.2f} | sim {sim_now:.0f} s | NaN {nan} | backwards stamps {backwards} | deepest overlap "
                  f"{_overlap_text(*probe.deepest)} | {watcher.messages} messages, {samples} "
                  "overlap samples", flush=True)
            minute_start, minute_sim, next_report = now, sim_now, now + 60.0
        if finished:
            break
        time.sleep(SAMPLE_PERIOD)
    commands.publish(Twist())

    total_wall = time.monotonic() - start
    nan, backwards, nan_by_topic, backwards_by_key = watcher.counts()
    final_rss, final_anonymous = _memory_megabytes(pid)
    growth = (final_anonymous - baseline_anonymous) / baseline_anonymous if baseline_anonymous else 0.0
    with watcher.lock:
        sim_now = watcher.sim_time or 0.0
    print(f"figure: soak {total_wall / 60.0:.1f} min: sim {sim_now:.0f} s (mean RTF {sim_now / total_wall:.2f}), RSS "
          f"{final_rss:.1f} MB, anonymous {baseline_anonymous or final_anonymous:.1f} MB after warm-up -> "
          f"{final_anonymous:.1f} MB ({100 * growth:+.1f} %), NaN {nan}, backwards stamps {backwards}, deepest overlap "
          f"{_overlap_text(*probe.deepest)}, {watcher.messages} messages checked", flush=True)
    if watcher.messages == 0 or sim_now <= 0.0:
        failures.append("nothing arrived from the simulation")
    if nan:
        failures.append(f"NaN in {nan_by_topic}")
    if backwards:
        failures.append(f"stamps went backwards: {backwards_by_key}")
    if growth > MEMORY_GROWTH_LIMIT:
        failures.append(f"the bridge's anonymous memory grew {100 * growth:.1f} % after the warm-up (limit "
                        f"{100 * MEMORY_GROWTH_LIMIT:.0f} %)")
    for failure in failures:
        print(f"mbot soak: FAILED: {failure}", file=sys.stderr)
    return 1 if failures else 0


def main(argv=None):
    parser = argparse.ArgumentParser(prog="mbot soak", description=__doc__.splitlines()[0])
    parser.add_argument("minutes", nargs="?", type=float, default=10.0, help="how long to run (default 10)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the random commands")
    args = parser.parse_args(argv)
    if not args.minutes > 0:
        parser.error("minutes must be positive")
    world_path = os.path.join(rospkg.RosPack().get_path("mbot_gazebo"), "worlds", "playground.world")
    log_dir = tempfile.mkdtemp(prefix="mbot_soak_")
    launch_log = os.path.join(log_dir, "roslaunch.log")
    with PrivateMaster() as master:
        os.environ.update(ROS_MASTER_URI=master.uri, ROS_LOG_DIR=log_dir)
        with open(launch_log, "w") as log:
            simulation = subprocess.Popen(
                ["roslaunch", "mbot_gazebo", "mbot_play_ground.launch", "gui:=false",
                 "real_time_factor:=0"],
                env=os.environ, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        print(f"mbot soak: {args.minutes:.1f} min, lidar mbot in the play ground at real-time factor 0, random "
              f"commands (seed {args.seed}; log: {launch_log})", file=sys.stderr, flush=True)
        try:
            status = soak(args.minutes * 60.0, world_path, args.seed, launch_log)
            if simulation.poll() is not None:
                print(f"mbot soak: FAILED: the simulation stopped (status {simulation.returncode}; see {launch_log})",
                      file=sys.stderr)
                status = 1
            return status
        finally:
            rospy.signal_shutdown("soak finished")
            stop_process_group(simulation)
