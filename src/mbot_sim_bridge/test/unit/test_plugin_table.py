"""The one plugin table: the ROS registry derived from it, both loaded per file name, no copy of the table
elsewhere, added plugin blocks checked."""
import ast
import functools
import importlib
import os
import pkgutil
import re
import subprocess
import sys

import pytest

from mbot_sim_bridge.core.joints.joint_states import JointStatePublisher
from mbot_sim_bridge.core.plugin import Plugin
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS, LazyClassTable, filename_of
from mbot_sim_bridge.core.joints.mimic_joint import MimicJoint
from mbot_sim_bridge.core.sensors.range_sensor import HectorSonar
from mbot_sim_bridge.plugins import registry
from mbot_sim_bridge.plugins.registry import REGISTRY

UNIT_TESTS = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(UNIT_TESTS, "..", "..", "..", ".."))
PACKAGE_SOURCE = os.path.join(UNIT_TESTS, "..", "..", "src")
README = os.path.join(UNIT_TESTS, "..", "..", "README.md")
# A dictionary entry keyed by a plugin's file name: how a copy of the table would look.
TABLE_ENTRY = re.compile(r"""["']lib\w+\.so["']\s*:""")


def test_the_ros_registry_has_every_table_entry_and_extends_its_core_class():
    assert list(REGISTRY) == list(CORE_PLUGINS)
    for filename, core_class in CORE_PLUGINS.items():
        assert issubclass(core_class, Plugin)
        assert issubclass(REGISTRY[filename], core_class), filename
        assert "core" not in REGISTRY[filename].__module__.split(".")


def test_no_copy_of_the_table_outside_its_module():
    listed = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard", "*.py"],
                            cwd=WORKSPACE, capture_output=True, text=True, check=True).stdout.split()
    sources = [path for path in listed if os.path.exists(os.path.join(WORKSPACE, path))]  # not those just deleted
    copies = [f"{path}:{number}" for path in sources if not path.endswith("core/plugin_table.py")
              for number, line in enumerate(open(os.path.join(WORKSPACE, path)), 1) if TABLE_ENTRY.search(line)]
    assert not copies, copies


def test_every_plugin_class_of_the_ros_package_is_reachable_through_the_registry():
    """A class in a module the registry never looks in would be dead: each one is some file name's class."""
    package = importlib.import_module("mbot_sim_bridge.plugins")
    registered = set(REGISTRY.values())
    for module_info in pkgutil.iter_modules(package.__path__):
        module = importlib.import_module(f"{package.__name__}.{module_info.name}")
        for plugin_class in registry.plugin_classes(module):
            in_use = plugin_class in registered or any(issubclass(ros_class, plugin_class) for ros_class in registered)
            assert in_use, f"{module.__name__}.{plugin_class.__name__}"


@functools.lru_cache(maxsize=None)  # every parametrized case reads the same files: parsed once per run
def _modules_imported_by_tests():
    """Test module -> the modules it imports (the checks of this file and of the README's tables left out)."""
    imported = {}
    for name in os.listdir(UNIT_TESTS):
        if name.endswith(".py") and name not in ("test_plugin_table.py", "test_readme.py"):
            tree = ast.parse(open(os.path.join(UNIT_TESTS, name)).read())
            imported[name] = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    return imported


@pytest.mark.parametrize("filename", sorted(CORE_PLUGINS))
def test_every_plugin_has_the_five_files_of_the_readme_recipe(filename):
    """README "Adding a plugin": the core module, the ROS module, the table line, the README's row and tag table,
    and a unit test of the core class."""
    core_class = CORE_PLUGINS[filename]  # the table line names a core class that imports
    core_module = core_class.__module__
    assert os.path.isfile(os.path.join(PACKAGE_SOURCE, *core_module.split(".")) + ".py")
    ros_module = registry.home_module(filename)
    assert os.path.isfile(os.path.join(PACKAGE_SOURCE, *ros_module.split(".")) + ".py"), f"{ros_module} is missing"
    assert f"`{filename}`" in open(README).read(), f"{filename} is not in the README's supported-plugin table"
    tests = [name for name, modules in _modules_imported_by_tests().items() if core_module in modules]
    assert tests, f"no unit test under test/unit imports {core_module}"


def test_a_second_file_name_shares_the_first_ones_ros_module():
    assert registry.home_module("libgazebo_ros_gpu_laser.so") == "mbot_sim_bridge.plugins.gazebo_ros_laser"
    assert REGISTRY["libgazebo_ros_gpu_laser.so"] is REGISTRY["libgazebo_ros_laser.so"]
    assert REGISTRY["libroboticsgroup_gazebo_mimic_joint_plugin.so"].__module__ == \
        "mbot_sim_bridge.plugins.roboticsgroup_upatras_gazebo_mimic_joint_plugin"


def test_a_missing_ros_module_is_named(monkeypatch):
    monkeypatch.setattr(registry, "home_module", lambda filename: "mbot_sim_bridge.plugins.gazebo_ros_no_such_drive")
    with pytest.raises(ImportError, match="libgazebo_ros_diff_drive.so: the ROS side of DiffDrive belongs in "
                                          "mbot_sim_bridge.plugins.gazebo_ros_no_such_drive, which is missing"):
        registry.find_ros_class("libgazebo_ros_diff_drive.so")


# Run in a fresh interpreter: this one has imported every plugin already.
IMPORTED_PLUGIN_MODULES = """
import sys
import mbot_sim_bridge.node
from mbot_sim_bridge.plugins.registry import REGISTRY
REGISTRY.get("libgazebo_ros_diff_drive.so")
print(" ".join(sorted(name for name in sys.modules if name.startswith("mbot_sim_bridge."))))
"""


def test_the_node_imports_only_the_plugins_it_looks_up():
    imported = set(subprocess.run([sys.executable, "-c", IMPORTED_PLUGIN_MODULES], capture_output=True, text=True,
                                  check=True).stdout.split())
    assert {"mbot_sim_bridge.core.drives.diff_drive", "mbot_sim_bridge.plugins.gazebo_ros_diff_drive"} <= imported
    # The simulation itself uses the joint state publisher (joints no plugin publishes) and the mimic joint.
    used = {f"mbot_sim_bridge.core.{module}" for module in ("drives.diff_drive", "joints.joint_states",
                                                            "joints.mimic_joint")}
    assert not ({core_class.__module__ for core_class in CORE_PLUGINS.values()} - used) & imported
    assert not {module for module in imported if module.startswith("mbot_sim_bridge.plugins.gazebo_ros_")} - {
        "mbot_sim_bridge.plugins.gazebo_ros_diff_drive"}
    assert "mbot_sim_bridge.core.ros_control.controller_table" not in imported


def test_a_lazy_table_loads_each_key_once_and_refuses_unknown_ones():
    loads = []
    table = LazyClassTable(["a", "b"], lambda key: loads.append(key) or type(key.upper(), (), {}))
    assert list(table) == ["a", "b"] and len(table) == 2 and loads == []
    assert table["b"] is table["b"] and loads == ["b"]
    assert table.get("c") is None and "c" not in table
    with pytest.raises(KeyError):
        table["c"]


def test_the_file_name_of_a_class():
    assert filename_of(JointStatePublisher) == "libgazebo_ros_joint_state_publisher.so"
    assert filename_of(MimicJoint) == "libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so"
    assert filename_of(HectorSonar) == "libhector_gazebo_ros_sonar.so"


def test_a_plugin_block_the_simulator_adds_uses_only_known_tags():
    element = JointStatePublisher.plugin_element("libgazebo_ros_joint_state_publisher.so", "states",
                                                 jointName="a, b", updateRate="50")
    assert {child.tag: child.text for child in element} == {"jointName": "a, b", "updateRate": "50"}
    with pytest.raises(ValueError, match="jointNames"):
        JointStatePublisher.plugin_element("libgazebo_ros_joint_state_publisher.so", "states", jointNames="a")
