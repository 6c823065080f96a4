"""A third-party Gazebo robot package, as users bring them: tests/third_party's minibot (TurtleBot3's layout)
builds in an overlay of this workspace although it depends on gazebo_ros, gazebo_plugins and
gazebo_ros_control, its package.xml export puts its models on the model path, and its own launch file runs
unchanged under rostest (third_party.test)."""
import ast
import os
import re
import shutil
import subprocess

import pytest

from ros_processes import TESTS, run

THIRD_PARTY = os.path.join(TESTS, "third_party")
PACKAGES = ("minibot_description", "minibot_gazebo")


@pytest.fixture(scope="module")
def overlay(tmp_path_factory):
    """(environment, src folder) of a catkin overlay of this workspace holding the minibot packages, built."""
    workspace = tmp_path_factory.mktemp("overlay")
    for package in PACKAGES:
        shutil.copytree(os.path.join(THIRD_PARTY, package), workspace / "src" / package)
    # catkin_make takes its workspace from $PWD before the current directory: both name the overlay.
    build = subprocess.run(["catkin_make", "-C", str(workspace), "-DCATKIN_ENABLE_TESTING=OFF"], cwd=workspace,
                           env=dict(os.environ, PWD=str(workspace)), capture_output=True, text=True, timeout=900)
    assert build.returncode == 0, (build.stdout + build.stderr)[-4000:]
    assert (workspace / "devel" / "setup.bash").is_file(), build.stdout[-4000:]
    sourced = subprocess.run(["bash", "-c", "source devel/setup.bash && env -0"], cwd=workspace, check=True,
                             env=dict(os.environ, PWD=str(workspace)), capture_output=True, text=True)
    environment = dict(line.split("=", 1) for line in sourced.stdout.split("\0") if "=" in line)
    # The model must come from the package's export, not from a path the user set.
    environment.pop("GAZEBO_MODEL_PATH", None)
    environment.update(ROS_HOME=str(workspace / "ros_home"), ROS_LOG_DIR=str(workspace / "log"))
    return environment, str(workspace / "src")


def test_package_export_is_on_the_model_path(overlay):
    environment, src = overlay
    result = run(["python3", "-c", "from mbot_sim_bridge.gazebo_paths import model_path, "
                  "resource_path; print(model_path()); print(resource_path())"], environment)
    assert result.returncode == 0, result.stderr
    model_path, resource_path = (ast.literal_eval(line) for line in result.stdout.splitlines()[-2:])
    assert os.path.join(src, "minibot_gazebo", "models") in model_path
    assert os.path.join(src, "minibot_gazebo") in resource_path


def test_the_packages_own_launch_file_runs_unchanged(overlay):
    environment, _ = overlay
    result = run(["rostest", "--text", os.path.join(THIRD_PARTY, "third_party.test")], environment, timeout=400)
    output = result.stdout + result.stderr
    for figure in re.findall(r"figure: (.*)", output):
        print(figure)
    assert result.returncode == 0 and "* FAILURES: 0" in output and "* ERRORS: 0" in output, output[-6000:]
