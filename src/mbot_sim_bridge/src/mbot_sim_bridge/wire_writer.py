"""The writer process: it writes the loop's serialized messages to the subscribers' sockets, on another core.

The ``gazebo`` node (loop_publishing.py) talks to it over one Unix stream socket, in frames:

- OPEN id, with the subscriber socket's descriptor attached (SCM_RIGHTS): write to it as ``id`` from now on;
- CLOSE id: rospy has closed that connection; drop the descriptor;
- DATA count length id*count payload: write the payload (a serialized message with its length prefix) to
  each of the ``count`` connections;
- SYNC token: answered with SYNCED token once everything before it is written (lockstep's guarantee).

It answers DEAD id when a write fails (the subscriber has gone), so the node closes the connection in rospy.
Standard library only: the process starts while the node loads its world and must not pay rospy's import.
"""
import collections
import signal
import socket
import struct
import sys

OPEN, CLOSE, DATA, SYNC = b"O", b"C", b"D", b"S"
DEAD, SYNCED = b"X", b"Y"
ID = struct.Struct("<cI")  # OPEN, CLOSE, SYNC and both answers: kind, id or token
DATA_HEADER = struct.Struct("<cII")  # kind, connection count, payload length
_RECEIVE_BYTES = 1 << 20


class WireWriter:
    def __init__(self, channel: socket.socket):
        self.channel = channel
        self.sockets = {}
        self.descriptors = collections.deque()  # received with OPEN frames, taken in order
        self.pending = bytearray()

    def run(self):
        while True:
            data, descriptors, _, _ = socket.recv_fds(self.channel, _RECEIVE_BYTES, 8)
            if not data:  # the node has stopped
                return
            # Linux ends a read at a message carrying descriptors, so they arrive with their OPEN frame.
            self.descriptors.extend(descriptors)
            self.pending += data
            used = self._handle(memoryview(self.pending))
            del self.pending[:used]

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
                self.sockets[number] = socket.socket(fileno=self.descriptors.popleft())
            elif kind == CLOSE:
                self._drop(number)
            elif kind == SYNC:
                self.channel.sendall(ID.pack(SYNCED, number))
            else:
                raise ValueError(f"wire writer: unknown frame kind {kind!r}")
        return offset

    def _write(self, connection: int, payload: memoryview):
        target = self.sockets.get(connection)
        if target is None:  # already reported dead; the node has not heard yet
            return
        try:
            target.sendall(payload)
        except OSError:
            self._drop(connection)
            self.channel.sendall(ID.pack(DEAD, connection))

    def _drop(self, connection: int):
        target = self.sockets.pop(connection, None)
        if target is not None:
            target.close()  # this process's copy only: closing a copy does not end the connection


def main():
    # Ctrl-C reaches the whole process group; the node decides when to stop, and this process ends with it
    # (end of file on the channel).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    WireWriter(socket.socket(fileno=int(sys.argv[1]))).run()


if __name__ == "__main__":
    main()
