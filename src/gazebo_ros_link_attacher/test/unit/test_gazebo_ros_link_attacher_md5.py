"""The generated Attach service carries gazebo_ros_link_attacher's md5 sum, computed from upstream's definition,
so clients built against upstream call the simulator's attach and detach services."""
from gazebo_ros_link_attacher.srv import Attach


def test_md5_is_upstreams():
    assert Attach._md5sum == "c91fb3be70ce66d19130d40294cf4bd5"
