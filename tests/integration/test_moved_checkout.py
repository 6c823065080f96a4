"""A checkout moved (or copied) to another folder works after ``./mbot setup``: the venv's and the devel space's
scripts name the folder they were made in, so setup notices the move and makes them again."""
import os
import shutil
import subprocess

import pytest

from ros_processes import TESTS, run

pytestmark = pytest.mark.long

CHECKOUT = os.path.dirname(TESTS)
# What was built in the old folder comes along; the venv is left behind to keep the copy small (setup makes it
# again in either case).
COPIED = (".catkin_workspace", "mbot", "worlds", "build", "devel")
# Of the workspace's packages, those `./mbot sim --help empty` reads (its launch files and their includes) and
# xacro, whose hook setup writes into the venv: what setup does on a move is the same for every package, and the
# message packages left out were most of the rebuild's CPU (63 s of CPU with all of them, 14 s with these).
COPIED_PACKAGES = ("CMakeLists.txt", "mbot_gazebo", "mbot_description", "mbot_sim_bridge", "gazebo_ros", "xacro")
# Likewise the venv: setup makes it again and installs the requirements, the same for each; the copy's
# requirements.txt keeps xacro alone, which setup's hook adapts (installing the whole list took 10 CPU s, xacro 1).
KEPT_REQUIREMENTS = ("xacro==",)


def test_a_moved_checkout_is_rebuilt_by_setup(tmp_path):
    moved = tmp_path / "moved"
    moved.mkdir()
    (moved / "src").mkdir()
    for name in COPIED + tuple(os.path.join("src", package) for package in COPIED_PACKAGES):
        source = os.path.join(CHECKOUT, name)
        if os.path.isdir(source):
            shutil.copytree(source, moved / name, symlinks=True, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(source, moved / name, follow_symlinks=False)  # src/CMakeLists.txt: catkin's link
    with open(os.path.join(CHECKOUT, "requirements.txt")) as requirements:
        kept = [line for line in requirements if line.startswith(KEPT_REQUIREMENTS)]
    assert len(kept) == len(KEPT_REQUIREMENTS), kept
    (moved / "requirements.txt").write_text("".join(kept))
    environment = {key: value for key, value in os.environ.items()
                   if not key.startswith(("ROS", "CMAKE_PREFIX", "PYTHONPATH", "VIRTUAL_ENV"))}
    setup = run([str(moved / "mbot"), "setup"], environment, timeout=600)
    assert setup.returncode == 0, setup.stdout + setup.stderr
    assert f"the checkout moved from {CHECKOUT}" in setup.stdout + setup.stderr
    script = moved / "devel" / "lib" / "mbot_gazebo" / "mbot_sim_launch"
    assert script.read_text().splitlines()[0] == f"#!{moved}/.venv/bin/python3"
    assert subprocess.run(["grep", "-rl", CHECKOUT, str(moved / "devel"), str(moved / ".venv" / "bin")],
                          capture_output=True, text=True).stdout == "", "files still name the old folder"
    listed = run([str(moved / "mbot"), "sim", "--help", "empty"], environment, timeout=120)
    assert listed.returncode == 0 and "lockstep:=false" in listed.stdout, listed.stdout + listed.stderr
