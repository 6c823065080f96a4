"""Fixtures for the core's unit tests: no ROS master, PyBullet in DIRECT mode."""
import os

import pytest

WORKSPACE_SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


def expand_xacro(relative_path: str, **arguments: str) -> str:
    """Run the real xacro on a file of mbot_description, as robot_description would hold it; ``arguments`` are
    its xacro:arg values (``name:=value`` on the command line)."""
    os.environ["ROS_PACKAGE_PATH"] = WORKSPACE_SRC + os.pathsep + os.environ.get("ROS_PACKAGE_PATH", "")
    import xacro_noetic as xacro
    # mappings: the xacro:arg values not given keep their defaults (xacro's Python API needs the map, even empty).
    return xacro.process_file(os.path.join(WORKSPACE_SRC, "mbot_description", relative_path),
                              mappings=arguments).toxml()


@pytest.fixture(scope="session")
def mbot_urdf() -> str:
    """The course's Gazebo mbot (mbot_gazebo.xacro), unchanged."""
    return expand_xacro("urdf/gazebo/mbot_gazebo.xacro")


@pytest.fixture(scope="session")
def laser_mbot_urdf() -> str:
    """The course's mbot with its rplidar (mbot_with_laser_gazebo.xacro)."""
    return expand_xacro("urdf/gazebo/mbot_with_laser_gazebo.xacro")
