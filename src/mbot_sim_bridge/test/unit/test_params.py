import logging
from xml.etree import ElementTree

import pytest

from mbot_sim_bridge.core.errors import ConfigError
from mbot_sim_bridge.core.params import Param, PluginParams, parse_bool

TABLE = (Param("wheelSeparation", float, 0.34), Param("publishTf", bool, True),
         Param("odometrySource", str, "world", choices=("world", "encoder")),
         Param("leftJoint", str, required=True))


def read(xml, ignored=()):
    return PluginParams(ElementTree.fromstring(xml), "TestPlugin(ns = /)", ignored).read(TABLE)


def test_present_tags_are_parsed():
    values = read("<plugin><wheelSeparation>0.24</wheelSeparation><publishTf>1</publishTf>"
                  "<odometrySource>encoder</odometrySource><leftJoint>left</leftJoint></plugin>")
    assert values == {"wheelSeparation": 0.24, "publishTf": True, "odometrySource": "encoder", "leftJoint": "left"}


def test_missing_tag_warns_once_with_its_default(caplog):
    with caplog.at_level(logging.WARNING):
        values = read("<plugin><leftJoint>l</leftJoint></plugin>")
        read("<plugin><leftJoint>l</leftJoint></plugin>")
    assert values["wheelSeparation"] == 0.34
    messages = [r.getMessage() for r in caplog.records if "wheelSeparation" in r.getMessage()]
    assert messages == ["TestPlugin(ns = /): missing <wheelSeparation>, default is 0.34"]


@pytest.mark.parametrize("xml, expected", [
    ("<plugin><leftJoint>l</leftJoint><publishTf>maybe</publishTf></plugin>", "<publishTf> has bad value 'maybe'"),
    ("<plugin><leftJoint>l</leftJoint><wheelSeparation>wide</wheelSeparation></plugin>",
     "<wheelSeparation> has bad value 'wide'"),
    ("<plugin><leftJoint>l</leftJoint><wheelSeparation>nan</wheelSeparation></plugin>",
     "<wheelSeparation> has bad value 'nan'"),
    ("<plugin><leftJoint>l</leftJoint><odometrySource>gps</odometrySource></plugin>",
     "<odometrySource> is 'gps'; expected one of world, encoder"),
    ("<plugin></plugin>", "missing required tag <leftJoint>"),
])
def test_bad_values_raise_config_error_naming_plugin_and_tag(xml, expected):
    with pytest.raises(ConfigError) as error:
        read(xml)
    assert str(error.value).startswith("TestPlugin(ns = /): ") and expected in str(error.value)


def test_unknown_tag_warns_and_lists_known_tags(caplog):
    with caplog.at_level(logging.WARNING):
        read("<plugin><leftJoint>l</leftJoint><wheelSeperation>0.2</wheelSeperation></plugin>")
    assert any("unknown tag <wheelSeperation> ignored; known tags: leftJoint, odometrySource, publishTf, "
               "wheelSeparation" in r.getMessage() for r in caplog.records)


def test_ignored_tags_do_not_warn(caplog):
    with caplog.at_level(logging.WARNING):
        read("<plugin><leftJoint>l</leftJoint><alwaysOn>true</alwaysOn></plugin>", ignored=("alwaysOn",))
    assert not any("alwaysOn" in r.getMessage() for r in caplog.records)


@pytest.mark.parametrize("text, value", [("true", True), ("TRUE", True), ("1", True), ("false", False),
                                         ("False", False), ("0", False)])
def test_booleans_as_gazebo_reads_them(text, value):
    assert parse_bool(text) is value
