"""The package README's diff-drive table is the one generated from the tags the plugin reads."""
import os

from mbot_sim_bridge.core.diff_drive import DIFF_DRIVE_PARAMS
from mbot_sim_bridge.core.params import params_table_markdown

README = os.path.join(os.path.dirname(__file__), "..", "..", "README.md")


def test_readme_lists_every_diff_drive_tag_with_its_default():
    assert params_table_markdown(DIFF_DRIVE_PARAMS) in open(README).read()
