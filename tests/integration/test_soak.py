"""./mbot soak: its overlap probe sees a robot inside a wall, and a short soak passes."""
import os
import subprocess

import pytest
from mbot_gazebo.soak import ROBOT, TUNNEL_DEPTH, OverlapProbe
from mbot_sim_bridge.core.geometry import pose_from_xyz_rpy

from ros_processes import TESTS

pytestmark = pytest.mark.long

ROOT = os.path.dirname(TESTS)
PLAYGROUND = os.path.join(ROOT, "worlds", "playground.world")


@pytest.fixture(scope="module")
def probe():
    model = os.path.join(ROOT, "src", "mbot_description", "urdf", "gazebo", "mbot_with_laser_gazebo.xacro")
    urdf = subprocess.run(["rosrun", "xacro", "xacro", "--inorder", model], capture_output=True, text=True,
                          check=True).stdout
    return OverlapProbe(PLAYGROUND, urdf)


def test_overlap_probe_tells_resting_from_tunnelled(probe):
    # On the floor in the open: wheel contacts only, a few millimetres at most.
    assert probe.measure({ROBOT: pose_from_xyz_rpy((0, 0, 0), (0, 0, 0))}) > -TUNNEL_DEPTH
    # Wholly inside the jersey barrier (a mesh; its near face at x = 5.0), in the brick box, sunk into the floor.
    assert probe.measure({ROBOT: pose_from_xyz_rpy((5.3, 0, 0.1), (0, 0, 0))}) < -TUNNEL_DEPTH
    assert probe.measure({ROBOT: pose_from_xyz_rpy((0.5, -3.0, 0.1), (0, 0, 0))}) < -TUNNEL_DEPTH
    assert probe.measure({ROBOT: pose_from_xyz_rpy((0, 0, -0.1), (0, 0, 0))}) < -TUNNEL_DEPTH


def test_short_soak_passes(tmp_path):
    """Nine seconds (the first half is the memory warm-up) of random driving at full speed: tens of seconds of
    sim time, the same checks as a long soak. Its log folder goes under the test's own."""
    result = subprocess.run([os.path.join(ROOT, "mbot"), "soak", "0.15"], capture_output=True, text=True,
                            timeout=600, env=dict(os.environ, TMPDIR=str(tmp_path)))
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    figures = [line for line in result.stdout.splitlines() if line.startswith("figure: soak")]
    assert figures, output
    print(figures[0])
