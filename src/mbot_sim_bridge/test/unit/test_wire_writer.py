"""The writer process's loop (wire_writer.py) in a thread, over socket pairs: a subscriber that stops reading
does not hold up the others, gets the newest whole messages when it reads again, and is reported once as
slow; SYNC is answered once the backlogs have drained; a subscriber that has gone is reported dead."""
import socket
import struct
import threading
import time

import pytest

from mbot_sim_bridge.wire_writer import (_BACKLOG_MESSAGES, CLOSE, DATA, DATA_HEADER, DEAD, ID, OPEN, SLOW, SYNC,
                                         SYNCED, WireWriter)

MESSAGES = 1000
BODY = 1000


def message(index: int) -> bytes:
    body = struct.pack("<I", index) + bytes(BODY - 4)
    return struct.pack("<I", len(body)) + body


def indices(data: bytes):
    """The index of every whole message in ``data``, which must hold whole messages only."""
    found, offset = [], 0
    while offset < len(data):
        length, = struct.unpack_from("<I", data, offset)
        assert length == BODY and offset + 4 + length <= len(data), "a message cut or mangled"
        found.append(struct.unpack_from("<I", data, offset + 4)[0])
        offset += 4 + length
    return found


def read_all(sock, timeout=0.2, into=None) -> bytes:
    """What ``sock`` delivers until it is quiet for ``timeout`` s, appended to ``into`` as it comes."""
    sock.settimeout(timeout)
    data = bytearray() if into is None else into
    try:
        while True:
            chunk = sock.recv(1 << 16)
            if not chunk:
                break
            data += chunk
    except socket.timeout:
        pass
    return bytes(data)


@pytest.fixture
def writer():
    node, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    thread = threading.Thread(target=WireWriter(theirs).run, daemon=True)
    thread.start()
    yield node
    node.close()  # the writer ends at end of file
    thread.join(5)
    assert not thread.is_alive()
    theirs.close()


def answers(node, wanted, timeout=5.0):
    """The writer's answers until ``wanted`` (kind, id) has come."""
    node.settimeout(timeout)
    received, data = [], b""
    deadline = time.monotonic() + timeout
    while wanted not in received and time.monotonic() < deadline:
        data += node.recv(4096)
        usable = len(data) - len(data) % ID.size
        received += list(ID.iter_unpack(data[:usable]))
        data = data[usable:]
    return received


def test_a_subscriber_that_stops_reading_holds_up_nobody(writer):
    stuck, stuck_far = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    healthy, healthy_far = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    stuck.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
    for number, sock in ((0, stuck), (1, healthy)):
        socket.send_fds(writer, [ID.pack(OPEN, number)], [sock.fileno()])
    got = bytearray()
    reader = threading.Thread(target=read_all, args=(healthy_far, 0.5, got), daemon=True)
    reader.start()
    ids = struct.pack("<2I", 0, 1)
    # In rounds the reading subscriber keeps up with (it shares this process's GIL with the writer's thread).
    for first in range(0, MESSAGES, 50):
        for index in range(first, first + 50):
            data = message(index)
            writer.sendall(DATA_HEADER.pack(DATA, 2, len(data)) + ids + data)
        deadline = time.monotonic() + 5.0
        while len(got) < (first + 50) * len(data) and time.monotonic() < deadline:
            time.sleep(0.001)
    assert (SLOW, 0) in answers(writer, (SLOW, 0))
    reader.join(10)
    assert indices(bytes(got)) == list(range(MESSAGES)), "the reading subscriber lost or reordered messages"
    # The stuck subscriber reads at last: whole messages, in order, the newest kept and the oldest dropped.
    late = indices(read_all(stuck_far))
    assert late == sorted(late) and late[-1] == MESSAGES - 1
    assert len(late) < MESSAGES and len(late) >= _BACKLOG_MESSAGES
    for sock in (stuck, stuck_far, healthy, healthy_far):
        sock.close()


def test_sync_waits_for_a_backlog_and_dead_subscribers_are_reported(writer):
    slow, slow_far = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    slow.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
    socket.send_fds(writer, [ID.pack(OPEN, 7)], [slow.fileno()])
    for index in range(20):
        data = message(index)
        writer.sendall(DATA_HEADER.pack(DATA, 1, len(data)) + struct.pack("<I", 7) + data)
    writer.sendall(ID.pack(SYNC, 42))
    writer.settimeout(0.3)
    with pytest.raises(socket.timeout):
        writer.recv(4096)  # nothing yet: the backlog is not written
    assert indices(read_all(slow_far)) == list(range(20))
    assert (SYNCED, 42) in answers(writer, (SYNCED, 42))
    slow_far.close()
    data = message(0)
    for _ in range(3):
        writer.sendall(DATA_HEADER.pack(DATA, 1, len(data)) + struct.pack("<I", 7) + data)
    assert (DEAD, 7) in answers(writer, (DEAD, 7))
    writer.sendall(ID.pack(CLOSE, 7))
    slow.close()
