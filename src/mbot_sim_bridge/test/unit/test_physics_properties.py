"""set_physics_properties and get_physics_properties' ODE fields (core/physics_properties.py): a new time step
keeps sim time going on from where it was and the mbot still drives within 5 %, a new gravity drops a crate as
g·t²/2 predicts, erp and solver iterations reach Bullet, ODE-only fields are warned about once; bad values are
refused naming the field and change nothing."""
import math

import pytest
from sensor_fixtures import measured_motion, plugin_of, world_simulation
from test_joint_efforts import CRATE

from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.drives.diff_drive import DiffDrive
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose

MOON = (0.0, 0.0, -1.62)


@pytest.fixture
def world(tmp_path, mbot_urdf):
    sim = world_simulation(tmp_path, CRATE)
    spawned = sim.spawn_robot(parse_robot(mbot_urdf, "model 'mbot'"), "mbot")
    sim.step(100)
    return sim, spawned


def set_physics(sim, time_step=0.001, rate=1000.0, gravity=(0.0, 0.0, -9.8), **ode):
    sim.set_physics(time_step, rate, gravity, sim.ode_config()._replace(**ode))


def test_a_new_step_and_gravity_act_from_where_the_simulation_is(world):
    sim, spawned = world
    assert sim.ode_config() == (False, 0, 50, 1.3, 0.0, 0.001, 100.0, 0.0, 0.2, 20)
    before = sim.sim_time
    set_physics(sim, time_step=0.002, rate=500.0, gravity=MOON, erp=0.3, sor_pgs_iters=80)
    assert (sim.step_size, sim.sim_time) == (0.002, pytest.approx(before, abs=1e-12))
    assert sim.engine.client.getPhysicsEngineParameters()["numSolverIterations"] == 80
    assert (sim.ode_config().erp, sim.ode_config().sor_pgs_iters) == (0.3, 80)
    sim.set_model_state("crate", Pose((2.0, 0.0, 1.0), IDENTITY.orientation))
    sim.step(250)
    assert sim.sim_time == pytest.approx(before + 0.5, abs=1e-9)
    drop = 1.0 - sim.engine.model_pose("crate").position[2]
    print(f"figure: crate dropped {drop:.4f} m in 0.5 s of moon gravity at a 2 ms step (g·t²/2 = 0.2025)")
    assert drop == pytest.approx(0.5 * 1.62 * 0.25, rel=0.02)
    drive = plugin_of(spawned, DiffDrive)
    speed, _ = measured_motion(sim, spawned, lambda: drive.set_command(0.3, 0.0), settle=1.0, window=0.5)
    print(f"figure: mbot at a 2 ms step: 0.3 m/s commanded -> {speed:.4f} m/s")
    assert speed == pytest.approx(0.3, rel=0.05)
    sim.reset(simulation=True)  # as Gazebo's: the physics stays as set, sim time starts again
    assert (sim.sim_time, sim.step_size, sim.engine.physics.gravity) == (0.0, 0.002, MOON)


@pytest.fixture(scope="module")
def crate_world(tmp_path_factory):
    with world_simulation(tmp_path_factory.mktemp("physics"), CRATE) as sim:
        yield sim


def test_fields_without_a_bullet_counterpart_are_warned_about_once(crate_world, caplog):
    sim = crate_world
    set_physics(sim, cfm=0.01, max_contacts=5)
    assert "cfm 0.01, max_contacts 5: no Bullet counterpart; ignored" in caplog.text
    assert (sim.ode_config().cfm, sim.ode_config().max_contacts) == (0.0, 20)


@pytest.mark.parametrize("change, message", [
    ({"time_step": math.nan}, r"time_step must be finite and in \[1e-05, 0.1\]; got nan"),
    ({"time_step": 0.0}, "time_step must be finite"),
    ({"time_step": 1.0}, "time_step must be finite"),
    ({"rate": math.inf}, "max_update_rate must be finite"),
    ({"rate": -1.0}, "max_update_rate must be finite"),
    ({"gravity": (0.0, math.nan, -9.8)}, "gravity.y must be finite"),
    ({"gravity": (0.0, 0.0, -1e300)}, "gravity.z must be finite"),
    ({"erp": 2.0}, r"ode_config.erp must be finite and in \[0, 1\]"),
    ({"sor_pgs_iters": 0}, "ode_config.sor_pgs_iters must be finite"),
    ({"contact_max_correcting_vel": math.inf}, "ode_config.contact_max_correcting_vel must be finite"),
    ({"cfm": math.nan}, "ode_config.cfm must be finite"),
])
def test_bad_values_are_refused_and_change_nothing(crate_world, change, message):
    sim = crate_world
    physics, iterations, now = sim.engine.physics, sim.engine.solver_iterations, sim.sim_time
    with pytest.raises(ModelError, match=message):
        set_physics(sim, **change)
    assert (sim.engine.physics, sim.engine.solver_iterations, sim.sim_time) == (physics, iterations, now)
