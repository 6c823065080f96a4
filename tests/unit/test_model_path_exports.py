"""Model and resource paths from package.xml exports (gazebo_ros's paths plugin, through rospack plugins), after
GAZEBO_MODEL_PATH / GAZEBO_RESOURCE_PATH; gzserver's command line turned into the bridge's parameters."""
import json
import os
import textwrap

import pytest
from mbot_sim_bridge.core.description.model_path import find_model_directory, find_world_file
from mbot_sim_bridge.gazebo_paths import model_path as default_model_path
from mbot_sim_bridge.gazebo_paths import package_exports, prefetch_package_exports
from mbot_sim_bridge.gazebo_paths import resource_path as default_resource_path
from mbot_sim_bridge.gzserver import CommandLineError, bridge_arguments

from ros_processes import TESTS

WORKSPACE = os.path.dirname(TESTS)


def make_package(root, name, depends=(), exports=""):
    folder = root / name
    folder.mkdir(parents=True)
    dependencies = "".join(f"<depend>{depend}</depend>" for depend in depends)
    (folder / "package.xml").write_text(textwrap.dedent(f"""\
        <?xml version="1.0"?>
        <package format="2">
          <name>{name}</name><version>1.0.0</version><description>test</description>
          <maintainer email="a@b.c">a</maintainer><license>BSD</license>
          <buildtool_depend>catkin</buildtool_depend>
          {dependencies}
          <export>{exports}</export>
        </package>
        """))
    return folder


def make_model(folder, name):
    (folder / name).mkdir(parents=True)
    (folder / name / "model.config").write_text(f"<model><name>{name}</name><sdf>model.sdf</sdf></model>")


@pytest.fixture
def packages(tmp_path, monkeypatch):
    """A package path with gazebo_ros, a world package exporting models and media, and a package that exports
    without depending on gazebo_ros (rospack plugins, like gazebo_ros, skips it)."""
    root = tmp_path / "packages"
    make_package(root, "gazebo_ros")
    worlds = make_package(root, "my_worlds", depends=["gazebo_ros"], exports=(
        '<gazebo_ros gazebo_model_path="${prefix}/models:${prefix}/more_models"/>'
        '<gazebo_ros gazebo_media_path="${prefix}"/>'))
    make_package(root, "stray", exports='<gazebo_ros gazebo_model_path="${prefix}/models"/>')
    make_model(worlds / "models", "pillar")
    make_model(tmp_path / "user_models", "pillar")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(root))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))  # rospack's cache
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    monkeypatch.delenv("GAZEBO_RESOURCE_PATH", raising=False)
    return root, tmp_path / "user_models"


def test_exports_of_packages_depending_on_gazebo_ros_with_prefix_replaced(packages):
    root, _ = packages
    worlds = str(root / "my_worlds")
    assert package_exports("gazebo_model_path") == [worlds + "/models", worlds + "/more_models"]
    assert package_exports("gazebo_media_path") == [worlds]
    assert package_exports("plugin_path") == []


def test_a_prefetched_rospack_run_gives_the_same_exports_and_is_used_once(packages, monkeypatch):
    root, _ = packages
    worlds = str(root / "my_worlds")
    prefetch_package_exports("gazebo_model_path")
    # The run started above is the one collected: with rospack gone from PATH now, only it can answer.
    monkeypatch.setenv("PATH", "/nonexistent")
    assert package_exports("gazebo_model_path") == [worlds + "/models", worlds + "/more_models"]
    assert package_exports("gazebo_model_path") == []  # the next call runs rospack again, and it is missing


def test_gazebo_model_path_comes_first_then_the_exports(packages, monkeypatch):
    root, user_models = packages
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(user_models))
    model_path = default_model_path()
    assert model_path[:3] == [str(user_models), str(root / "my_worlds" / "models"),
                              str(root / "my_worlds" / "more_models")]
    assert find_model_directory("pillar", model_path) == str(user_models / "pillar")
    monkeypatch.delenv("GAZEBO_MODEL_PATH")
    assert find_model_directory("pillar", default_model_path()) == str(root / "my_worlds" / "models" / "pillar")


def test_resource_path_and_world_lookup(packages, monkeypatch, tmp_path):
    root, _ = packages
    monkeypatch.setenv("GAZEBO_RESOURCE_PATH", str(tmp_path / "media"))
    resource_path = default_resource_path()
    assert resource_path[:2] == [str(tmp_path / "media"), str(root / "my_worlds")]
    assert resource_path[-1] == WORKSPACE  # holds worlds/empty.world, as Gazebo's share folder does
    assert find_world_file("worlds/empty.world", resource_path) == os.path.join(WORKSPACE, "worlds", "empty.world")
    assert find_world_file("worlds/nowhere.world", resource_path) is None


def test_no_gazebo_ros_on_the_package_path_means_no_exports(monkeypatch, tmp_path):
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    assert package_exports("gazebo_model_path") == []


def parameters(argv):
    return {argument.split(":=")[0]: json.loads(argument.split(":=", 1)[1])
            for argument in argv if argument.startswith("_") and not argument.startswith("__")}


def test_gzserver_command_line_becomes_the_bridge_parameters():
    argv = bridge_arguments("gzserver", ["gzserver", "-u", "--verbose", "-e", "ode", "--seed", "3",
                                         "-s", "libgazebo_ros_api_plugin.so", "worlds/empty.world",
                                         "__name:=gazebo", "__log:=/tmp/x.log"])
    assert argv[:3] == ["gzserver", "__name:=gazebo", "__log:=/tmp/x.log"]
    assert parameters(argv) == {"_world_name": os.path.join(WORKSPACE, "worlds", "empty.world"),
                                "_paused": True, "_seed": 3}
    assert argv[-1] == "--verbose"
    assert parameters(bridge_arguments("gazebo", ["gazebo"], gui=True)) == {
        "_world_name": os.path.join(WORKSPACE, "worlds", "empty.world"), "_paused": False, "_gui": True}


@pytest.mark.parametrize("argv, message", [
    (["gzserver", "-p", "run.log"], "does not play Gazebo logs"),
    (["gzserver", "--iters", "10"], "runs until stopped"),
    (["gzserver", "worlds/nowhere.world"], "world file worlds/nowhere.world not found"),
])
def test_gzserver_refuses_what_it_cannot_do(argv, message):
    with pytest.raises(CommandLineError, match=message):
        bridge_arguments("gzserver", argv)


def test_gzserver_warns_about_options_without_effect(capsys):
    bridge_arguments("gzserver", ["gzserver", "-r", "-e", "bullet", "-s", "libother.so", "-g", "libgui.so"])
    errors = capsys.readouterr().err.splitlines()
    assert errors == ["gzserver: system plugin libother.so is not emulated; ignored",
                      "gzserver: GUI plugin libgui.so is not emulated; ignored",
                      "gzserver: recording (-r, --record_*) is not supported; running without recording",
                      "gzserver: -e bullet: the bridge's engine is always Bullet"]
