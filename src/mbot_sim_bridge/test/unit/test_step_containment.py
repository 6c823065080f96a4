"""What raises inside the physics step or a rebuild is contained: a plugin's per-step recorder, one model's part of
``Engine.step`` (its wheel contacts, the correction of its placement), Bullet's own step, a model that cannot be
built again on reset_simulation. That model (or plugin) is frozen or removed with one error, the others keep their
poses and the loop keeps stepping."""
import logging
import math
import os
from types import SimpleNamespace

import numpy as np
import pybullet
import pytest

from mbot_sim_bridge.core.description.mesh import TriangleMesh, write_binary_stl
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.simulation import Simulation

WORLDS = os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "worlds")
BYSTANDER_TOLERANCE = 1e-4  # m
DIVISION_BY_ZERO = ZeroDivisionError("float division by zero")  # what the injected faults raise
CRATE = """<sdf version="1.6"><model name="crate"><link name="link">
  <inertial><mass>1</mass><inertia><ixx>0.04</ixx><iyy>0.04</iyy><izz>0.04</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision></link></model></sdf>"""


def errors(caplog, *texts):
    return [record for record in caplog.records
            if record.levelno >= logging.ERROR and all(text in record.getMessage() for text in texts)]


def mbot_with_crate(mbot_urdf, tmp_path, registry=CORE_PLUGINS):
    """The course mbot at the origin and a crate 2 m away, settled; returns the simulation and the crate's pose."""
    sim = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), registry)
    sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
    path = tmp_path / "crate.world"
    path.write_text(spawn_world_xml(CRATE, "crate", pose_from_xyz_rpy((2, 0, 0.25), (0, 0, 0))))
    sim.add_world(parse_world(str(path)))
    sim.step(300)
    return sim, sim.engine.model_pose("crate").position


def assert_crate_still(sim, resting):
    assert math.dist(sim.engine.model_pose("crate").position, resting) < BYSTANDER_TOLERANCE


def failing_once(function, error):
    """``function`` raising ``error`` at its first call, and the list that records that call."""
    failures = []

    def call(*arguments):
        if not failures:
            failures.append(arguments)
            raise error
        return function(*arguments)
    return call, failures


class DriveWithFailingRecorder(DiffDrive):
    """A diff drive whose per-step recorder (as the IMU's) raises: recorders run inside Engine.step."""

    def step_recorder(self, now):
        def record():
            raise DIVISION_BY_ZERO
        return record


def test_a_plugin_whose_recorder_raises_is_disabled_and_the_rest_runs(mbot_urdf, tmp_path, caplog):
    registry = {filename: DriveWithFailingRecorder if plugin_class is DiffDrive else plugin_class
                for filename, plugin_class in CORE_PLUGINS.items()}
    sim, resting = mbot_with_crate(mbot_urdf, tmp_path, registry)
    try:
        assert not any(isinstance(plugin, DiffDrive) for plugin in sim.models["mbot"].plugins)
        assert len(errors(caplog, "model 'mbot': plugin GazeboRosDiffDrive", "disabled: ZeroDivisionError")) == 1
        assert sim.models["mbot"].plugins, "the joint state publisher runs on"
        sim.step(100)
        assert sim.sim_time == pytest.approx(0.4)
        assert_crate_still(sim, resting)
    finally:
        sim.close()


def wheels_fail(sim):
    """A stand-in for the mbot's wheel contacts whose arithmetic raises (Engine.step applies them every step)."""
    wheels, _ = failing_once(lambda: None, DIVISION_BY_ZERO)
    sim.engine._wheels[sim.models["mbot"].robot.body] = SimpleNamespace(apply=wheels)
    sim.engine._refresh_before_step()  # as Engine.set_surfaces does once it has the wheels


def placement_correction_fails(sim):
    """The correction of a body placed into another (Engine._bound_correction) raising for the mbot, put 5 cm into
    the ground."""
    sim.engine._point_velocity, _ = failing_once(sim.engine._point_velocity, DIVISION_BY_ZERO)
    sim.set_model_state("mbot", pose_from_xyz_rpy((0, 0, -0.05), (0, 0, 0)))


@pytest.mark.parametrize("part, fail", [("wheel contacts", wheels_fail),
                                        ("placement correction", placement_correction_fails)])
def test_a_model_whose_part_of_the_step_raises_is_frozen_and_reset_brings_it_back(mbot_urdf, tmp_path, caplog, part,
                                                                                  fail):
    sim, resting = mbot_with_crate(mbot_urdf, tmp_path)
    try:
        drive = next(plugin for plugin in sim.models["mbot"].plugins if isinstance(plugin, DiffDrive))
        fail(sim)
        drive.set_command(0.3, 0.0)
        sim.step(500)
        assert sim.sim_time == pytest.approx(0.8)
        said = errors(caplog, f"model 'mbot': its part of the physics step failed ({part}: ZeroDivisionError", "frozen")
        assert len(said) == 1 and len(errors(caplog)) == 1, [record.getMessage() for record in caplog.records]
        assert math.dist(sim.engine.model_pose("mbot").position, (0, 0, 0)) < 0.01, "frozen at its spawn pose"
        assert_crate_still(sim, resting)
        sim.reset(simulation=False)
        drive.set_command(0.3, 0.0)
        sim.step(500)
        assert sim.engine.model_pose("mbot").position[0] > 0.05, "reset_world ends the freeze"
        assert_crate_still(sim, resting)
    finally:
        sim.close()


def test_bullets_own_step_raising_skips_the_batch_and_the_world_steps_on(mbot_urdf, tmp_path, caplog):
    sim, resting = mbot_with_crate(mbot_urdf, tmp_path)
    try:
        client = sim.engine.client
        client.stepSimulation, failures = failing_once(client.stepSimulation, pybullet.error("stepSimulation failed."))
        sim.step(100)
        assert failures and sim.sim_time == pytest.approx(0.4)
        assert len(errors(caplog, "the physics step at 0.300 s failed (error: stepSimulation failed.)")) == 1
        assert len(errors(caplog)) == 1
        assert sim.model_names() == ["ground_plane", "crate", "mbot"]
        assert_crate_still(sim, resting)
    finally:
        sim.close()


def test_a_model_that_cannot_be_built_again_is_removed_on_reset_simulation(mbot_urdf, tmp_path, caplog):
    """A robot whose mesh file is gone since it was spawned: reset_simulation rebuilds every other model."""
    mesh = tmp_path / "block.stl"
    write_binary_stl(TriangleMesh(np.array([[0, 0, 0], [0.2, 0, 0], [0, 0.2, 0], [0, 0, 0.2]], dtype=float),
                                  np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])), str(mesh))
    block = (f'<robot name="block"><link name="body"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
             f'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><mesh filename="{mesh}"/>'
             '</geometry></collision></link></robot>')
    sim, _ = mbot_with_crate(mbot_urdf, tmp_path)
    try:
        sim.spawn_robot(parse_robot(block, "model 'block'"), "block", pose_from_xyz_rpy((0, 2, 0.1), (0, 0, 0)))
        mesh.unlink()
        sim.reset(simulation=True)
        assert sim.model_names() == ["ground_plane", "crate", "mbot"]
        assert len(errors(caplog, "model 'block': could not be built again (ModelError:", "cannot read mesh",
                          "removed")) == 1
        assert len(errors(caplog)) == 1
        sim.step(300)
        assert sim.sim_time == pytest.approx(0.3)
        assert math.dist(sim.engine.model_pose("crate").position, (2, 0, 0.25)) < 1e-3
    finally:
        sim.close()
