"""The world's lights (core/lights.py): read from <light> and model://sun as Gazebo has them, got, set and deleted
by name with upstream's messages; bad values are refused naming the field and the light is left as it was."""
import math

import pytest

from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.errors import ModelError
from mbot_sim_bridge.core.geometry import IDENTITY, Pose
from mbot_sim_bridge.core.lights import SUN
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.simulation import Simulation

WORLD = """<sdf version="1.6"><world name="default">
  <include><uri>model://sun</uri></include>
  <light name="lamp" type="spot"><pose>1 2 3 0 0 0</pose><diffuse>0.5 0.4 0.3 1</diffuse><cast_shadows>true
    </cast_shadows><attenuation><range>20</range><constant>0.5</constant><linear>0.1</linear></attenuation>
    <direction>0 0 -1 7</direction></light>
</world></sdf>"""
LAMP = dict(cast_shadows=False, diffuse=(1.0, 0.0, 0.0, 1.0), specular=(0.0, 0.0, 0.0, 1.0),
            attenuation=(1.0, 0.0, 0.0), direction=(0.0, 1.0, 0.0), pose=Pose((0.0, 0.0, 5.0), IDENTITY.orientation))


@pytest.fixture
def lights(tmp_path):
    path = tmp_path / "lights.world"
    path.write_text(WORLD)
    with Simulation(parse_world(str(path), []), CORE_PLUGINS) as sim:
        yield sim.lights


def test_the_world_files_lights_are_read_as_gazebo_has_them(lights, caplog):
    assert lights.get("sun") == SUN
    lamp = lights.get("lamp")
    assert (lamp.type, lamp.cast_shadows, lamp.diffuse, lamp.attenuation, lamp.range, lamp.pose.position) == (
        "spot", True, (0.5, 0.4, 0.3, 1.0), (0.5, 0.1, 0.0), 20.0, (1.0, 2.0, 3.0))
    assert lamp.direction == (0.0, 0.0, -1.0)  # four numbers: the default kept, and said
    said = [record.getMessage() for record in caplog.get_records("setup")]
    assert "light 'lamp': <direction> '0 0 -1 7' is not 3 numbers; the default (0.0, 0.0, -1.0) is kept" in said


@pytest.mark.parametrize("field, value, message", [
    ("diffuse", (math.nan, 0.0, 0.0, 1.0), "diffuse must be finite"),
    ("specular", (0.0, math.inf, 0.0, 1.0), "specular must be finite"),
    ("attenuation", (1e300, 0.0, 0.0), "attenuation must be finite and at most 1e\\+06"),
    ("direction", (0.0, -math.inf, 0.0), "direction must be finite"),
    ("pose", Pose((math.nan, 0.0, 0.0), IDENTITY.orientation), "position.x is nan"),
    ("pose", Pose((0.0, 0.0, 1e300), IDENTITY.orientation), "position.z = 1e\\+300 is outside"),
])
def test_bad_values_are_refused_and_the_light_stays(lights, field, value, message):
    before = lights.get("lamp")
    with pytest.raises(ModelError, match="^setLightProperties: light 'lamp': .*" + message):
        lights.set("lamp", **{**LAMP, field: value})
    assert lights.get("lamp") == before


def test_a_light_is_set_and_deleted_by_name_with_upstreams_messages(lights):
    for action in (lambda: lights.get("nowhere"), lambda: lights.set("nowhere", **LAMP),
                   lambda: lights.delete("nowhere")):
        with pytest.raises(ModelError, match="Requested light nowhere not found!$"):
            action()
    lights.set("lamp", **LAMP)
    lamp = lights.get("lamp")
    assert (lamp.type, lamp.range) == ("spot", 20.0)  # not in the request: kept
    assert {field: getattr(lamp, field) for field in LAMP} == LAMP
    lights.delete("lamp")
    with pytest.raises(ModelError, match="^DeleteLight: Requested light lamp not found!$"):
        lights.delete("lamp")
    assert list(lights.lights) == ["sun"]
