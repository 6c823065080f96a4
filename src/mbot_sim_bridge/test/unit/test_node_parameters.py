"""The simulator node's rate parameters (~pub_clock_frequency, ~joint_state_rate): a finite number of Hz, or the
node stops with one line naming the parameter."""
import pytest
import rospy

from mbot_sim_bridge import node
from mbot_sim_bridge.core.errors import BridgeError


@pytest.fixture
def parameter(monkeypatch):
    """Sets what the parameter server answers for every name."""
    def set_value(value):
        monkeypatch.setattr(rospy, "get_param", lambda name, default=None: value)
        monkeypatch.setattr(rospy, "resolve_name", lambda name: "/gazebo/" + name.lstrip("~"))
    return set_value


@pytest.mark.parametrize("value, rate", [(10, 10.0), ("2.5", 2.5), (0.0, 0.0), (-1.0, -1.0), (1e300, 1e300)])
def test_a_finite_rate_is_taken(parameter, value, rate):
    parameter(value)
    assert node._rate_param("~joint_state_rate", 10.0) == rate


@pytest.mark.parametrize("value", [float("nan"), float("inf"), "-inf", "fast", True, None, [10]])
def test_anything_else_stops_the_node_naming_the_parameter(parameter, value):
    parameter(value)
    with pytest.raises(BridgeError, match=r"^parameter /gazebo/joint_state_rate: not a finite rate in Hz, got "):
        node._rate_param("~joint_state_rate", 10.0)
