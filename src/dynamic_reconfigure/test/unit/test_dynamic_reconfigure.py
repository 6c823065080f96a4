"""The generated dynamic_reconfigure types carry upstream's (ros/dynamic_reconfigure noetic-devel) md5 sums,
computed with genmsg from upstream's definitions, so rqt_reconfigure and other clients talk to the server; and
the server's messages describe and hold a configuration as upstream's encoding does."""
import dynamic_reconfigure.msg as msg
import pytest
from dynamic_reconfigure.server import Parameter, describe, encode
from dynamic_reconfigure.srv import Reconfigure

UPSTREAM_MESSAGE_MD5 = {
    "BoolParameter": "23f05028c1a699fb83e22401228c3a9e",
    "Config": "958f16a05573709014982821e6822580",
    "ConfigDescription": "757ce9d44ba8ddd801bb30bc456f946f",
    "DoubleParameter": "d8512f27253c0f65f928a67c329cd658",
    "Group": "9e8cd9e9423c94823db3614dd8b1cf7a",
    "GroupState": "a2d87f51dc22930325041a2f8b1571f8",
    "IntParameter": "65fedc7a0cbfb8db035e46194a350bf1",
    "ParamDescription": "7434fcb9348c13054e0c3b267c8cb34d",
    "SensorLevels": "6322637bee96d5489db6e2127c47602c",
    "StrParameter": "bc6ccc4a57f61779c8eaae61e9f422e0",
}
PARAMETERS = [Parameter("rate", "double", 1.5, 0.0, 10.0, "Hz", 1), Parameter("count", "int", 3, 0, 9, "n", 2),
              Parameter("on", "bool", True, False, True, "switch", 4), Parameter("name", "str", "a", "", "", "s", 8)]


@pytest.mark.parametrize("name", list(UPSTREAM_MESSAGE_MD5))
def test_message_md5_matches_upstream(name):
    message_type = getattr(msg, name)
    assert message_type._type == f"dynamic_reconfigure/{name}"
    assert message_type._md5sum == UPSTREAM_MESSAGE_MD5[name]
    message_type()


def test_service_md5_matches_upstream_and_only_upstreams_types_are_generated():
    assert (Reconfigure._type, Reconfigure._md5sum) == ("dynamic_reconfigure/Reconfigure",
                                                        "bb125d226a21982a4a98760418dc2672")
    generated = {name for name in dir(msg) if isinstance(getattr(msg, name), type) and hasattr(getattr(msg, name),
                                                                                               "_md5sum")}
    assert generated == set(UPSTREAM_MESSAGE_MD5)


def test_a_configuration_is_encoded_by_type_in_the_default_group():
    config = encode(PARAMETERS, {"rate": 2.5, "count": 4, "on": False, "name": "b"})
    assert [(item.name, item.value) for item in config.doubles] == [("rate", 2.5)]
    assert [(item.name, item.value) for item in config.ints] == [("count", 4)]
    assert [(item.name, item.value) for item in config.bools] == [("on", False)]
    assert [(item.name, item.value) for item in config.strs] == [("name", "b")]
    assert [(group.name, group.state, group.id, group.parent) for group in config.groups] == [("Default", True, 0, 0)]
    description = describe(PARAMETERS)
    (group,) = description.groups
    assert (group.name, group.type, group.id, group.parent) == ("Default", "", 0, 0)
    assert [(item.name, item.type, item.level) for item in group.parameters] == [
        ("rate", "double", 1), ("count", "int", 2), ("on", "bool", 4), ("name", "str", 8)]
    assert (description.max.doubles[0].value, description.min.ints[0].value, description.dflt.strs[0].value) == (
        10.0, 0, "a")
