"""The writer process: it writes the loop's serialized messages to the subscribers' sockets, on another core.

The ``gazebo`` node (loop_publishing.py) talks to it over one Unix stream socket, in frames:

- OPEN id, with the subscriber socket's descriptor attached (SCM_RIGHTS): write to it as ``id`` from now on;
- CLOSE id: rospy has closed that connection; drop the descriptor;
- DATA count length id*count payload: write the payload (a serialized message with its length prefix) to
  each of the ``count`` connections;
- SYNC token: answered with SYNCED token once everything before it is written (lockstep's guarantee).

It answers DEAD id when a write fails (the subscriber has gone), so the node closes the connection in rospy,
and SLOW id once when a subscriber has stopped keeping up.

No write waits for a subscriber: a socket that takes no more keeps a backlog of whole messages, written as it
drains, and past _BACKLOG_MESSAGES or _BACKLOG_BYTES its oldest messages are dropped, as roscpp's per-subscriber
queues drop them in Gazebo. A blocking write to one stalled subscriber (a node stopped with Ctrl-Z, a rospy
callback that hangs, a lidar cloud read slower than it comes) used to stop this process, then the loop's
writes to it, then the simulation and its /clock, until that subscriber read again.
Standard library only: the process starts while the node loads its world and must not pay rospy's import.
"""
import collections
import select
import signal
import socket
import struct
import sys

OPEN, CLOSE, DATA, SYNC = b"O", b"C", b"D", b"S"
DEAD, SYNCED, SLOW = b"X", b"Y", b"L"
ID = struct.Struct("<cI")  # OPEN, CLOSE, SYNC and both answers: kind, id or token
DATA_HEADER = struct.Struct("<cII")  # kind, connection count, payload length
_RECEIVE_BYTES = 1 << 20
# A subscriber's backlog: about a second of a 100 Hz topic, and room for dozens of 3D lidar clouds.
_BACKLOG_MESSAGES = 100
_BACKLOG_BYTES = 1 << 23


class _Connection:
    """A subscriber socket and the whole messages it has not taken yet (the first may be partly written)."""

    def __init__(self, sock: socket.socket):
        self.socket = sock
        self.backlog = collections.deque()
        self.backlog_bytes = 0
        self.head_started = False
        self.reported_slow = False


class WireWriter:
    def __init__(self, channel: socket.socket):
        self.channel = channel
        self.sockets = {}
        self.descriptors = collections.deque()  # received with OPEN frames, taken in order
        self.pending = bytearray()
        self.poller = select.poll()
        self.poller.register(channel, select.POLLIN)
        self.by_descriptor = {}  # descriptor -> connection id, for the sockets with a backlog
        self.syncs = []  # SYNC tokens waiting for the backlogs to drain

    def run(self):
        channel = self.channel.fileno()
        while True:
            for descriptor, _ in self.poller.poll():
                if descriptor != channel:
                    self._drain(self.by_descriptor.get(descriptor))
                    continue
                data, descriptors, _, _ = socket.recv_fds(self.channel, _RECEIVE_BYTES, 8)
                if not data:  # the node has stopped
                    return
                # Linux ends a read at a message carrying descriptors, so they arrive with their OPEN frame.
                self.descriptors.extend(descriptors)
                self.pending += data
                used = self._handle(memoryview(self.pending))
                del self.pending[:used]
            if self.syncs and not self.by_descriptor:
                for token in self.syncs:
                    self.channel.sendall(ID.pack(SYNCED, token))
                self.syncs.clear()

    def _handle(self, view: memoryview) -> int:
        """Carry out every whole frame in ``view``; returns the bytes used."""
        offset, end = 0, len(view)
        while offset < end:
            kind = view[offset:offset + 1].tobytes()
            if kind == DATA:
                if end - offset < DATA_HEADER.size:
                    break
                _, count, length = DATA_HEADER.unpack_from(view, offset)
                ids_start = offset + DATA_HEADER.size
                payload_start = ids_start + 4 * count
                if end - payload_start < length:
                    break
                payload = view[payload_start:payload_start + length]
                for connection in struct.unpack_from(f"<{count}I", view, ids_start):
                    self._write(connection, payload)
                offset = payload_start + length
                continue
            if end - offset < ID.size:
                break
            _, number = ID.unpack_from(view, offset)
            offset += ID.size
            if kind == OPEN:
                self.sockets[number] = _Connection(socket.socket(fileno=self.descriptors.popleft()))
            elif kind == CLOSE:
                self._drop(number)
            elif kind == SYNC:  # answered once every backlog has drained (run)
                self.syncs.append(number)
            else:
                raise ValueError(f"wire writer: unknown frame kind {kind!r}")
        return offset

    def _write(self, number: int, payload: memoryview):
        connection = self.sockets.get(number)
        if connection is None:  # already reported dead; the node has not heard yet
            return
        if connection.backlog:
            self._queue(number, connection, bytes(payload))
            return
        written = self._send(number, connection, payload)
        if written is not None and written < len(payload):
            connection.head_started = written > 0
            self._queue(number, connection, bytes(payload[written:]))

    def _send(self, number: int, connection: _Connection, data) -> "int | None":
        """What the socket took without waiting (MSG_DONTWAIT: the descriptor's blocking mode is rospy's, shared
        with the node); None when the subscriber has gone."""
        try:
            return connection.socket.send(data, socket.MSG_DONTWAIT)
        except BlockingIOError:
            return 0
        except OSError:
            self._drop(number)
            self.channel.sendall(ID.pack(DEAD, number))
            return None

    def _queue(self, number: int, connection: _Connection, data: bytes):
        connection.backlog.append(memoryview(data))
        connection.backlog_bytes += len(data)
        keep = 1 if connection.head_started else 0  # a message partly written must be finished
        while len(connection.backlog) > keep + 1 and (len(connection.backlog) > _BACKLOG_MESSAGES
                                                      or connection.backlog_bytes > _BACKLOG_BYTES):
            connection.backlog_bytes -= len(connection.backlog[keep])
            del connection.backlog[keep]
            if not connection.reported_slow:
                connection.reported_slow = True
                self.channel.sendall(ID.pack(SLOW, number))
        descriptor = connection.socket.fileno()
        if descriptor not in self.by_descriptor:
            self.by_descriptor[descriptor] = number
            self.poller.register(descriptor, select.POLLOUT)

    def _drain(self, number):
        connection = self.sockets.get(number)
        if connection is None:
            return
        while connection.backlog:
            head = connection.backlog[0]
            written = self._send(number, connection, head)
            if written is None:
                return
            connection.backlog_bytes -= written
            if written < len(head):
                connection.backlog[0] = head[written:]
                connection.head_started = connection.head_started or written > 0
                return
            connection.backlog.popleft()
            connection.head_started = False
        self._unwatch(connection)

    def _unwatch(self, connection: _Connection):
        descriptor = connection.socket.fileno()
        if self.by_descriptor.pop(descriptor, None) is not None:
            self.poller.unregister(descriptor)

    def _drop(self, number: int):
        connection = self.sockets.pop(number, None)
        if connection is not None:
            self._unwatch(connection)
            connection.socket.close()  # this process's copy only: closing a copy does not end the connection


def main():
    # Ctrl-C reaches the whole process group; the node decides when to stop, and this process ends with it
    # (end of file on the channel).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    WireWriter(socket.socket(fileno=int(sys.argv[1]))).run()


if __name__ == "__main__":
    main()
