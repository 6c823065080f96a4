"""Every relative link in the workspace's READMEs and docs/ pages reaches a file, and every #anchor a heading of it."""
import os
import re

import pytest

WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# The checkout's own files: not the venv, the build output or git's folder.
SKIPPED = (".venv", ".git", "build", "devel", "out")
READMES = sorted(os.path.relpath(os.path.join(folder, "README.md"), WORKSPACE)
                 for folder, subfolders, names in os.walk(WORKSPACE)
                 if os.path.relpath(folder, WORKSPACE).split(os.sep)[0] not in SKIPPED and "README.md" in names)
READMES += sorted(os.path.join("docs", name) for name in os.listdir(os.path.join(WORKSPACE, "docs"))
                  if name.endswith(".md"))


def anchors(path):
    """The anchors GitHub gives a file's headings: lower case, punctuation dropped, spaces to hyphens."""
    headings = re.findall(r"(?m)^#+ (.*)$", open(path).read())
    return {re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-") for heading in headings}


def test_the_readmes_are_found():
    assert "README.md" in READMES and "tests/README.md" in READMES


@pytest.mark.parametrize("readme", READMES)
def test_every_link_reaches_its_file_and_heading(readme):
    path = os.path.join(WORKSPACE, readme)
    for link in re.findall(r"\]\(([^)\s]+)\)", open(path).read()):
        if re.match(r"[a-z]+://", link):
            continue
        target, _, anchor = link.partition("#")
        target = os.path.normpath(os.path.join(os.path.dirname(path), target)) if target else path
        assert os.path.exists(target), f"{readme}: {link} names a missing file"
        if anchor and target.endswith(".md"):
            assert anchor in anchors(target), f"{readme}: {link} names no heading of {os.path.basename(target)}"
