"""SDF models with joints, sensors and plugins: read as the URDF robots are (core/description/sdf_model.py) and
simulated by the same path, from world files, includes and spawn_sdf_model."""
import math
import os

import numpy as np
import pytest

from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.simulation import Simulation

HERE = os.path.dirname(os.path.abspath(__file__))
TEST_WORLDS = os.path.join(HERE, "..", "worlds")

# The pendulum of double_pendulum.world: two uniform rods of mass m and length l, each hinged at its top end,
# the lower one at the upper one's bottom end; centre of mass a = l/2 below each hinge, moment about it m l²/12.
G, MASS, LENGTH = 9.8, 1.0, 0.5
CENTRE, MOMENT = LENGTH / 2.0, 0.0208333


def normal_mode_periods():
    """Small-angle periods and mode shapes of the double pendulum, from its Lagrangian.

    With θ1, θ2 the rods' angles from the vertical, for small angles T = ½ θ̇ᵀ M θ̇ and V = ½ θᵀ K θ with
    M = [[m a² + I + m l², m l a], [m l a, m a² + I]] (the lower rod's centre moves with l θ1 + a θ2) and
    K = g diag(m a + m l, m a). The normal modes solve K v = ω² M v; each period is 2π/ω.
    Returns (period, (θ1, θ2) shape) for the slow and the fast mode.
    """
    inertia = np.array([[MASS * CENTRE ** 2 + MOMENT + MASS * LENGTH ** 2, MASS * LENGTH * CENTRE],
                        [MASS * LENGTH * CENTRE, MASS * CENTRE ** 2 + MOMENT]])
    stiffness = G * np.diag([MASS * CENTRE + MASS * LENGTH, MASS * CENTRE])
    squared, shapes = np.linalg.eig(np.linalg.solve(inertia, stiffness))
    order = np.argsort(squared)
    return [(2.0 * math.pi / math.sqrt(squared[k]), shapes[:, k] / shapes[0, k]) for k in order]


@pytest.fixture(scope="module")
def pendulum():
    simulation = Simulation(parse_world(os.path.join(TEST_WORLDS, "double_pendulum.world")), CORE_PLUGINS)
    yield simulation
    simulation.close()


def upward_crossings(times, values):
    return [t0 - v0 * (t1 - t0) / (v1 - v0)
            for t0, t1, v0, v1 in zip(times, times[1:], values, values[1:]) if v0 < 0.0 <= v1]


@pytest.mark.parametrize("mode", [0, 1], ids=["slow mode", "fast mode"])
def test_an_sdf_double_pendulum_swings_with_the_periods_of_its_normal_modes(pendulum, mode):
    """Started in one normal mode (0.02 rad on the shoulder; the elbow's angle is the rods' difference), the
    shoulder swings at that mode's period within 2 %."""
    period, shape = normal_mode_periods()[mode]
    pendulum.reset(simulation=True)
    upper, lower = 0.02 * shape
    pendulum.set_model_configuration("double_pendulum", ["shoulder", "elbow"], [upper, lower - upper])
    robot = pendulum.models["double_pendulum"].robot
    times, angles = [], []
    for _ in range(int(2.5 * period / pendulum.step_size)):
        pendulum.step(1)
        times.append(pendulum.sim_time)
        angles.append(robot.joint_state(["shoulder"])[0][0])
    crossings = upward_crossings(times, angles)
    assert len(crossings) >= 2
    measured = float(np.mean(np.diff(crossings)))
    assert measured == pytest.approx(period, rel=0.02), f"measured {measured:.4f} s, predicted {period:.4f} s"
    assert max(np.abs(angles)) == pytest.approx(0.02, rel=0.1)  # one mode only: the amplitude stays


def test_the_pendulum_is_a_robot_with_its_joints_and_a_joint_state_publisher(pendulum):
    spawned = pendulum.models["double_pendulum"]
    assert spawned.robot.movable_joints == ["shoulder", "elbow"]
    assert spawned.robot.model.anchored  # its shoulder joint's parent is the world
    assert [type(plugin).__name__ for plugin in spawned.plugins] == ["JointStatePublisher"]
    assert "double_pendulum" not in pendulum.world_models
