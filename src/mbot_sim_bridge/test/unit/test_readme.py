"""The plugin reference's tag tables (docs/plugins.md) are the ones generated from the tables the plugins read,
and the package README's supported-plugin table names every plugin."""
import os

import pytest

from mbot_sim_bridge.core.params import params_table_markdown
from mbot_sim_bridge.plugins.registry import REGISTRY

PACKAGE = os.path.join(os.path.dirname(__file__), "..", "..")
README = os.path.join(PACKAGE, "README.md")
REFERENCE = os.path.join(PACKAGE, "..", "..", "docs", "plugins.md")


@pytest.mark.parametrize("filename", sorted(REGISTRY))
def test_the_reference_lists_every_tag_of_every_plugin_with_its_default_and_range(filename):
    plugin_class = REGISTRY[filename]
    assert f"`{filename}`" in open(README).read(), f"{filename} is not in the README's supported-plugin table"
    reference = open(REFERENCE).read()
    assert params_table_markdown(plugin_class.PARAMS) in reference
    if plugin_class.SENSOR_PARAMS:
        assert params_table_markdown(plugin_class.SENSOR_PARAMS) in reference
