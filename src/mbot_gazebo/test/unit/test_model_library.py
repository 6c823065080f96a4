"""mbot_gazebo.model_library: what ./mbot models lists and insert accepts (no ROS master)."""
import glob
import os
import xml.etree.ElementTree as ET

import pytest

from mbot_gazebo.model_library import (BUILTIN_MODELS, UnknownModel, find_model, format_table, instance_name,
                                       list_models)
from mbot_sim_bridge.core.description.sdf_spawn import spawn_world_xml
from mbot_sim_bridge.core.description.sdf_world import BUILTIN_MODEL_NAMES, parse_world
from mbot_sim_bridge.core.geometry import IDENTITY

HERE = os.path.dirname(os.path.abspath(__file__))
WORLDS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "..", "worlds"))
WORKSPACE_MODELS = os.path.join(WORLDS, "models")
# Gazebo database names added here as look-alikes built from primitives.
LOOK_ALIKES = ("cafe_table", "table", "construction_barrel", "cardboard_box", "coke_can", "wood_cube_10cm")
SIMPLE_SHAPES = ("unit_box", "unit_cylinder", "unit_sphere")


def write_model(directory, name, description="A test model.", title=None):
    model = directory / name
    model.mkdir(parents=True)
    (model / "model.config").write_text(
        f"<model><name>{title or name}</name><sdf version='1.6'>model.sdf</sdf>"
        f"<description>{description}</description></model>")
    (model / "model.sdf").write_text(
        f"<sdf version='1.6'><model name='{name}'><static>true</static><link name='l'><collision name='c'>"
        "<geometry><box><size>1 1 1</size></box></geometry></collision></link></model></sdf>")
    return model


def used_by_shipped_worlds():
    names = set()
    for path in glob.glob(os.path.join(WORLDS, "*.world")):
        for uri in ET.parse(path).getroot().iter("uri"):
            if uri.text.strip().startswith("model://"):
                names.add(uri.text.strip()[len("model://"):].split("/")[0])
    return names


def test_lists_every_model_the_shipped_worlds_use_and_the_look_alikes(monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    names = [model.name for model in list_models()]
    assert names == sorted(names)
    missing = (used_by_shipped_worlds() | set(LOOK_ALIKES) | set(SIMPLE_SHAPES)) - set(names)
    assert not missing


@pytest.mark.parametrize("name", LOOK_ALIKES + SIMPLE_SHAPES)
def test_look_alikes_say_so_and_load(name, tmp_path):
    (model,) = [model for model in list_models([WORKSPACE_MODELS]) if model.name == name]
    assert "built here from" in model.description
    assert model.path == os.path.join(WORKSPACE_MODELS, name)
    # Inserted as spawn_model -database does it: an include in a one-model world.
    xml = f"<sdf version='1.6'><world name='w'><include><uri>model://{name}</uri></include></world></sdf>"
    world = tmp_path / "spawn.world"
    world.write_text(spawn_world_xml(xml, name, IDENTITY))
    (description,) = parse_world(str(world), [WORKSPACE_MODELS]).models
    assert description.shapes
    # Everything stands on the ground at the model origin and nothing sinks below it.
    assert min(shape.bounds()[0][2] for shape in description.shapes) == pytest.approx(0.0, abs=1e-6)
    assert description.static == (name in ("cafe_table", "table"))
    if not description.static:
        assert sum(link.mass for link in description.links) > 0.0


def test_description_path_and_title_come_from_model_config(tmp_path):
    write_model(tmp_path, "widget", description="  A widget,\n   on two lines. ", title="Widget")
    (model,) = [model for model in list_models([str(tmp_path)]) if model.name == "widget"]
    assert (model.title, model.description) == ("Widget", "A widget, on two lines.")
    assert model.path == str(tmp_path / "widget")
    table = format_table([model])
    assert "widget  A widget, on two lines." in table and str(tmp_path / "widget") in table


def test_first_directory_on_the_model_path_wins_and_folders_without_config_are_skipped(tmp_path):
    write_model(tmp_path / "first", "cone", description="first")
    write_model(tmp_path / "second", "cone", description="second")
    (tmp_path / "second" / "not_a_model").mkdir()
    models = list_models([str(tmp_path / "first"), str(tmp_path / "second"), str(tmp_path / "missing")])
    assert [model.description for model in models if model.name == "cone"] == ["first"]
    assert "not_a_model" not in [model.name for model in models]


def test_gazebo_model_path_comes_first(tmp_path, monkeypatch):
    write_model(tmp_path, "cafe_table", description="mine")
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path))
    assert find_model("cafe_table", list_models()).description == "mine"


def test_built_in_models_are_the_bridges():
    assert set(BUILTIN_MODELS) == set(BUILTIN_MODEL_NAMES)
    assert [model.path for model in list_models([]) if model.name == "sun"] == ["(built in)"]


def test_unknown_name_lists_the_nearest():
    models = list_models([WORKSPACE_MODELS])
    with pytest.raises(UnknownModel) as error:
        find_model("cafe_tabel", models)
    message = str(error.value)
    assert "no model 'cafe_tabel'" in message and "nearest: cafe_table" in message and "\n" not in message
    with pytest.raises(UnknownModel, match="lists all"):
        find_model("zzzzzzzz", models)


def test_repeated_names_get_gazebo_suffixes():
    assert instance_name("unit_box", ["ground_plane"]) == "unit_box"
    assert instance_name("unit_box", ["unit_box"]) == "unit_box_0"
    assert instance_name("unit_box", ["unit_box", "unit_box_0", "unit_box_2"]) == "unit_box_1"
