"""Fixtures shared by the workspace's pure-core unit tests (no ROS master)."""
import logging

import pybullet
import pytest
from mbot_sim_bridge.core.log import forget_warnings
from pybullet_utils.bullet_client import BulletClient


@pytest.fixture
def client():
    """A PyBullet physics client of the test's own, in DIRECT mode."""
    bullet = BulletClient(connection_mode=pybullet.DIRECT)
    yield bullet
    bullet.disconnect()


@pytest.fixture(autouse=True)
def fresh_warnings():
    """Each test sees its own once-only warnings, and the bridge's log level as it starts (a robot's
    rosDebugLevel tag changes it for the whole process)."""
    forget_warnings()
    logger = logging.getLogger("rosout.mbot_sim_bridge")
    level = logger.level
    yield
    logger.setLevel(level)
