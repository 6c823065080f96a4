"""Fixtures for the core's unit tests: no ROS master, PyBullet in DIRECT mode."""
import pytest
from sensor_fixtures import course_urdf

from mbot_sim_bridge.core.simulation import Simulation


@pytest.fixture(autouse=True)
def simulations_closed(monkeypatch):
    """Every Simulation a test opens is closed when the test ends (closing twice is harmless), not left to the
    garbage collector, which would disconnect its PyBullet client at some later moment of another test."""
    opened = []
    open_simulation = Simulation.__init__

    def recorded(simulation, *args, **kwargs):
        open_simulation(simulation, *args, **kwargs)
        opened.append(simulation)
    monkeypatch.setattr(Simulation, "__init__", recorded)
    yield
    for simulation in opened:
        simulation.close()


@pytest.fixture(scope="session")
def mbot_urdf() -> str:
    """The course's Gazebo mbot (mbot_gazebo.xacro), unchanged."""
    return course_urdf("mbot_gazebo")


@pytest.fixture(scope="session")
def laser_mbot_urdf() -> str:
    """The course's mbot with its rplidar (mbot_with_laser_gazebo.xacro)."""
    return course_urdf("mbot_with_laser_gazebo")
