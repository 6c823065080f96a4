"""Shared builders for the ros_control tests: a Simulation with a robot whose gazebo_ros_control finds its
controller YAML on a parameter tree, and controller switches as the service performs them."""
import os
import threading

import yaml
from sensor_fixtures import WORKSPACE_SRC, expanded

from mbot_sim_bridge.core.ros_control.gazebo_ros_control import GazeboRosControlPlugin
from mbot_sim_bridge.core.parameters import Parameters
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation

WORLDS = os.path.join(WORKSPACE_SRC, "..", "worlds")
MBOT_YAML = os.path.join(WORKSPACE_SRC, "mbot_gazebo", "config", "mbot_ros_control.yaml")
ROBOTS = os.path.join(WORKSPACE_SRC, "ros_control_test_robots")
CAR = os.path.join(WORKSPACE_SRC, "car_description", "urdf", "car.urdf.xacro")
CAR_CONFIG = os.path.join(WORKSPACE_SRC, "car_gazebo", "config", "car_{}_controllers.yaml")


def load_yaml(path):
    with open(path) as stream:
        return yaml.safe_load(stream)


def simulate(urdf, controllers, name="robot", parameters=None, package_uris=str, namespace=None,
             world=os.path.join(WORLDS, "empty.world")):
    """A Simulation of ``world`` with the robot spawned from ``urdf``, which is also its robot_description parameter;
    its gazebo_ros_control finds ``controllers`` (a controller YAML) in its namespace (``namespace``, by default
    the model name) and the other ``parameters`` ({absolute name: value}) where they are named."""
    tree = {"robot_description": urdf}
    for path, value in [((namespace or name) + "/" + key, config) for key, config in controllers.items()] + list(
            (parameters or {}).items()):
        *parents, leaf = path.strip("/").split("/")
        node = tree
        for parent in parents:
            node = node.setdefault(parent, {})
        node[leaf] = value
    sim = Simulation(parse_world(world), CORE_PLUGINS,
                     parameters=Parameters(tree), package_uris=package_uris)
    spawned = sim.spawn_robot(parse_robot(package_uris(urdf), f"model '{name}'"), name)
    plugin = next(plugin for plugin in spawned.plugins if isinstance(plugin, GazeboRosControlPlugin))
    return sim, spawned, plugin


def switch(sim, manager, start=(), stop=(), strictness=2):
    """A switch as the service does it: requested from another thread, performed by the next control update."""
    result = []
    thread = threading.Thread(target=lambda: result.append(manager.switch(list(start), list(stop), strictness)))
    thread.start()
    while thread.is_alive():
        sim.step(1)
    return result[0]


def switch_stepping(sim, manager, start):
    """Start the controllers ``start`` at the very next step, deterministically: the switch waits by stepping."""
    def step_until(done, timeout):
        while not done.is_set():
            sim.step(1)
        return True
    assert manager.switch(list(start), [], 2, wait=step_until)


def recording_batches(sim):
    """The step counts of the loop's batches, recorded from now on."""
    batches, engine_step = [], sim.engine.step

    def record(count, after_each=()):
        batches.append(count)
        engine_step(count, after_each)
    sim.engine.step = record
    return batches


def expand_xacro_arm(interface):
    return expanded(os.path.join(ROBOTS, "urdf", "two_joint_arm.urdf.xacro"), interface=interface)


def expand_xacro_car(steering):
    return expanded(CAR, steering=steering)


def car(steering):
    """car_gazebo's car with ``steering`` (ackermann or four_wheel), its car_controller started."""
    sim, spawned, plugin = simulate(expand_xacro_car(steering), load_yaml(CAR_CONFIG.format(steering)), "car",
                                    namespace="/")
    return sim, spawned, plugin, start_controllers(sim, plugin, "car_controller", "joint_state_controller")


def arm(interface):
    urdf = expand_xacro_arm(interface)
    return simulate(urdf, load_yaml(os.path.join(ROBOTS, "config", f"arm_{interface.lower()}.yaml")), "arm")


def start_controllers(sim, plugin, *names):
    """Load and start the controllers ``names`` as the spawner does; returns the first one's controller."""
    manager = plugin.manager
    for name in names:
        assert manager.load(name, plugin.urdf), f"{name} did not load"
    assert switch(sim, manager, list(names))
    return manager.find(names[0]).controller


def run_until_ended(sim, controller, seconds=10.0):
    """Step until an action controller (trajectory or gripper) has ended a goal; that outcome."""
    for _ in range(int(seconds / 0.01)):
        sim.step(10)
        if controller.ended:
            return controller.ended.pop(0)
    raise AssertionError(f"no outcome within {seconds} s")
