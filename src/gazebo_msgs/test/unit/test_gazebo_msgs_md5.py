"""The generated gazebo_msgs types carry gazebo_ros_pkgs' (noetic-devel) md5 sums, computed with genmsg from
upstream's definitions, so nodes built against upstream's gazebo_msgs talk to the bridge."""
import pytest

import gazebo_msgs.msg as msg
import gazebo_msgs.srv as srv

UPSTREAM_MD5 = {
    msg.ContactState: "48c0ffb054b8c444f870cecea1ee50d9",
    msg.ContactsState: "acbcb1601a8e525bf72509f18e6f668d",
    msg.ModelStates: "48c080191eb15c41858319b4d8a609c2",
    msg.ModelState: "9330fd35f2fcd82d457e54bd54e10593",
    msg.LinkState: "0818ebbf28ce3a08d48ab1eaa7309ebe",
    srv.SpawnModel: "9ed9c82c96abe1a00c3e8cdaeee24413",
    srv.GetModelState: "4c515e936d3319c9610c559c60bfc3d4",
    srv.SetModelState: "5b3ab0281d4f5445def017e3a2e4a07b",
    srv.ApplyBodyWrench: "585b9f9618aa0581b207e2f2d90866bc",
    srv.BodyRequest: "5eade9afe7f232d78005bd0cafeab755",
}


@pytest.mark.parametrize("message_type", list(UPSTREAM_MD5), ids=lambda t: t._type)
def test_md5_matches_upstream(message_type):
    assert message_type._md5sum == UPSTREAM_MD5[message_type]
