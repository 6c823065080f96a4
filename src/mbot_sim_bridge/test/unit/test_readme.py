"""The package README's tag tables are the ones generated from the tables the plugins read."""
import os

import pytest

from mbot_sim_bridge.core.params import params_table_markdown
from mbot_sim_bridge.plugins.registry import REGISTRY

README = os.path.join(os.path.dirname(__file__), "..", "..", "README.md")


@pytest.mark.parametrize("filename", sorted(REGISTRY))
def test_readme_lists_every_tag_of_every_plugin_with_its_default_and_range(filename):
    plugin_class = REGISTRY[filename]
    text = open(README).read()
    assert f"`{filename}`" in text, f"{filename} is not in the supported-plugin table"
    assert params_table_markdown(plugin_class.PARAMS) in text
    if plugin_class.SENSOR_PARAMS:
        assert params_table_markdown(plugin_class.SENSOR_PARAMS) in text
