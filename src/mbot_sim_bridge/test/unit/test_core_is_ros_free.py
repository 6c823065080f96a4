"""The simulation core must run without ROS: no rospy, tf2 or message imports anywhere in core/, sub-packages
included."""
import ast
import os

import pytest

CORE = os.path.join(os.path.dirname(__file__), "..", "..", "src", "mbot_sim_bridge", "core")
FORBIDDEN = ("rospy", "tf2_ros", "tf", "rosgraph", "roslib", "rospkg", "genpy")


def _imported_modules(path):
    tree = ast.parse(open(path).read(), path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module


MODULES = sorted(os.path.relpath(os.path.join(folder, name), CORE)
                 for folder, _, names in os.walk(CORE) for name in names if name.endswith(".py"))


def test_every_sub_package_is_walked():
    assert {"ros_control/controller_manager.py", "drives/diff_drive.py", "simulation.py"} <= set(MODULES)


@pytest.mark.parametrize("module", MODULES)
def test_core_module_imports_no_ros(module):
    for name in _imported_modules(os.path.join(CORE, module)):
        top = name.split(".")[0]
        assert top not in FORBIDDEN and not top.endswith("_msgs"), f"{module} imports {name}"
