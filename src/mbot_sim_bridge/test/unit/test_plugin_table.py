"""The one plugin table: the ROS registry derived from it, no copy of it elsewhere, added plugin blocks checked."""
import os
import re
import subprocess

import pytest

from mbot_sim_bridge.core.joint_states import JointStatePublisher
from mbot_sim_bridge.core.plugin import Plugin
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS, filename_of
from mbot_sim_bridge.plugins.registry import REGISTRY

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
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


def test_the_file_name_of_a_class():
    assert filename_of(JointStatePublisher) == "libgazebo_ros_joint_state_publisher.so"


def test_a_plugin_block_the_simulator_adds_uses_only_known_tags():
    element = JointStatePublisher.plugin_element("libgazebo_ros_joint_state_publisher.so", "states",
                                                 jointName="a, b", updateRate="50")
    assert {child.tag: child.text for child in element} == {"jointName": "a, b", "updateRate": "50"}
    with pytest.raises(ValueError, match="jointNames"):
        JointStatePublisher.plugin_element("libgazebo_ros_joint_state_publisher.so", "states", jointNames="a")
