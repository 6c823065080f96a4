"""The simulator's and spawn_model's start-up without garbage collection: off before the scripts' first import,
back on (with the start-up's objects frozen) once the node is up."""
import ast
import gc
import inspect
import os
import textwrap

import pytest

from mbot_sim_bridge import node, processes, spawn_model

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SCRIPTS = ("gazebo_ros/scripts/gzserver", "gazebo_ros/scripts/gazebo", "gazebo_ros/scripts/spawn_model",
           "mbot_sim_bridge/scripts/gzserver", "mbot_sim_bridge/scripts/spawn_model")


@pytest.fixture
def collection_restored():
    yield
    gc.unfreeze()
    gc.enable()


def test_end_start_up_turns_collection_back_on_with_the_objects_so_far_frozen(collection_restored):
    gc.disable()
    processes.end_start_up()
    assert gc.isenabled()
    assert gc.get_freeze_count() > 1000


@pytest.mark.parametrize("script", SCRIPTS)
def test_a_script_switches_collection_off_before_its_first_import(script):
    with open(os.path.join(SRC, script)) as source:
        statements = ast.parse(source.read()).body[1:]  # after the docstring
    assert ast.unparse(statements[0]) == "import gc"
    assert ast.unparse(statements[1]) == "gc.disable()"
    assert isinstance(statements[2], ast.ImportFrom)


@pytest.mark.parametrize("main", [node.main, spawn_model.main])
def test_the_scripts_main_turns_it_back_on(main):
    """A call in main's code (a comment or a string naming it would not count)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(main)))
    called = [call.func for call in ast.walk(tree) if isinstance(call, ast.Call)]
    assert any(getattr(function, "id", getattr(function, "attr", None)) == "end_start_up" for function in called)
