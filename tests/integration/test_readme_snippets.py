"""The README's Python snippets run as written, against the simulator its text starts for them."""
import os
import re

import pytest

from ros_processes import TESTS, run

README = os.path.join(os.path.dirname(TESTS), "README.md")


def python_snippets():
    return re.findall(r"```python\n(.*?)```", open(README).read(), re.S)


def test_the_readme_has_python_snippets():
    assert python_snippets(), "no ```python block in the README: this test would check nothing"


@pytest.mark.parametrize("snippet", python_snippets(), ids=lambda snippet: snippet.splitlines()[-2][:40])
def test_a_readme_snippet_runs(ros_env, launch, tmp_path, snippet):
    # Each snippet is written for `./mbot sim empty lockstep:=true`, which runs this launch file headless.
    simulator = launch("mbot_gazebo", "mbot_world.launch", "gui:=false", "lockstep:=true")
    script = tmp_path / "snippet.py"
    script.write_text(snippet)
    result = run(["python3", str(script)], ros_env, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr + simulator.log_path.read_text()[-2000:]
    assert re.search(r"^[1-9]\d* /odom messages by sim time 0\.500 s$", result.stdout, re.M), result.stdout
