"""The generated four_wheel_steering_msgs types carry four_wheel_steering_msgs 1.1's md5 sums, computed from
upstream's definitions, so four_wheel_steering_controller's clients built against upstream talk to the simulator."""
import pytest
from four_wheel_steering_msgs.msg import FourWheelSteering, FourWheelSteeringStamped


@pytest.mark.parametrize("message_type, md5", [(FourWheelSteering, "04dd0f55e1f168668af1e2587a7cdd2a"),
                                               (FourWheelSteeringStamped, "9226582df815bc6df9e3206bc05923af")])
def test_md5_is_upstreams(message_type, md5):
    assert message_type._md5sum == md5
