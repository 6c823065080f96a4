"""subscriptions.py's look at a socket: it must work on descriptors past 1024, where select.select refuses
(a simulator with many connections has them); drain would otherwise take such a connection for idle."""
import os
import resource
import select
import socket

import pytest

from mbot_sim_bridge.subscriptions import readable_within

HIGH_DESCRIPTOR = 1500


def test_readable_within_sees_bytes_on_a_descriptor_past_1024():
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft <= HIGH_DESCRIPTOR:
        if hard != resource.RLIM_INFINITY and hard <= HIGH_DESCRIPTOR:
            pytest.skip(f"the descriptor limit ({hard}) does not reach {HIGH_DESCRIPTOR}")
        resource.setrlimit(resource.RLIMIT_NOFILE, (HIGH_DESCRIPTOR + 1, hard))
    reader, writer = socket.socketpair()
    high = os.dup2(reader.fileno(), HIGH_DESCRIPTOR)
    try:
        with pytest.raises(ValueError):
            select.select([high], [], [], 0.0)
        assert not readable_within(high, 0)
        writer.send(b"x")
        assert readable_within(high, 1000)
    finally:
        os.close(high)
        reader.close()
        writer.close()
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
