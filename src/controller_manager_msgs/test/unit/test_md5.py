"""The generated types carry ros_control 0.20's md5 sums (computed with genmsg from upstream's definitions), so
nodes built against upstream's controller_manager_msgs talk to this workspace's and the other way round."""
import pytest

import controller_manager_msgs.msg as msg
import controller_manager_msgs.srv as srv

UPSTREAM_MD5 = {
    msg.ControllerState: "aeb6b261d97793ab74099a3740245272",
    msg.ControllerStatistics: "697780c372c8d8597a1436d0e2ad3ba8",
    msg.ControllersStatistics: "a154c347736773e3700d1719105df29d",
    msg.HardwareInterfaceResources: "f25b55cbf1d1f76e82e5ec9e83f76258",
    srv.ListControllerTypes: "c1d4cd11aefa9f97ba4aeb5b33987f4e",
    srv.ListControllers: "1341feb2e63fa791f855565d0da950d8",
    srv.LoadController: "647e5c54b8d6468952d8d31f1efe96c0",
    srv.ReloadControllerLibraries: "40e8c411fd1797d2e2c486018f846040",
    srv.SwitchController: "b29a7abc673b2c54c14b54e50f8d06a5",
    srv.UnloadController: "647e5c54b8d6468952d8d31f1efe96c0",
}


@pytest.mark.parametrize("message_type", list(UPSTREAM_MD5), ids=lambda t: t._type)
def test_md5_matches_upstream(message_type):
    assert message_type._md5sum == UPSTREAM_MD5[message_type]


def test_switch_controller_constants():
    assert (srv.SwitchControllerRequest.BEST_EFFORT, srv.SwitchControllerRequest.STRICT) == (1, 2)
