"""The loop's publishers, written to the subscribers' sockets by another process (wire_writer.py).

PyBullet holds the GIL while it steps, so no thread of this process can write beside it, and rospy's
synchronous per-connection ``sendall`` to loopback TCP was about a fifth of the loop (README, Profile). Here
the loop serializes each message once, as rospy does, and appends it with the ids of its connections to a
batch; the batch goes to the writer process in one write per loop pass, and the writer, which holds a copy of
each subscriber socket, does the per-connection writes on the other core. rospy still accepts the connections,
does the handshake and counts them; it no longer writes to them.

This takes over the part of rospy's ``_PublisherImpl.publish`` that serializes and writes (sequence number,
header.seq, the length prefix, statistics), for publishers that are neither latched nor queued; a rospy
Publisher has no hook for writing elsewhere.
"""
import contextlib
import errno
import io
import socket
import struct
import subprocess
import sys
import threading
import time
import warnings
from typing import Dict, List, Optional, Tuple

import numpy as np
import rospy
from rospy.msg import serialize_message

from . import wire_writer
from .wire_writer import CLOSE, DATA, DATA_HEADER, DEAD, ID, OPEN, SLOW, SYNC, SYNCED

_STOP_SECONDS = 1.0
_ANSWERS_READ_SECONDS = 0.05
# The longest a message waits in the batch (wall time) while the loop runs flat out, and the batch's size cap.
COALESCE_SECONDS = 0.001
_COALESCE_BYTES = 1 << 16


class WriterStopped(RuntimeError):
    pass


class LoopPublishing:
    """The writer process and the batch the loop fills; flushed by the loop after each pass."""

    def __init__(self):
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        self.process = subprocess.Popen([sys.executable, "-S", wire_writer.__file__, str(theirs.fileno())],
                                        pass_fds=[theirs.fileno()])
        theirs.close()
        self._channel = ours
        self._batch = bytearray()
        self._buffer = io.BytesIO()
        self._ids: Dict[object, Tuple[int, object]] = {}  # rospy connection -> (id, its publisher impl)
        self._connections: Dict[int, object] = {}
        self._next_id = 0
        self._next_token = 0
        self._answers = bytearray()
        self._next_answers_read = 0.0
        self._batch_started = 0.0
        self._failure: Optional[OSError] = None
        # Publishing and flushing come from the loop thread; the lock keeps a publish from another thread whole.
        self._lock = threading.RLock()

    def publish(self, impl, message):
        with self._impl_lock(impl), self._lock:
            connections = self._open_connections(impl)
            if not connections:
                return
            # The batch's own buffer, not the impl's: rospy's shutdown closes that from another thread.
            buffer = self._buffer
            impl.seq += 1
            serialize_message(buffer, impl.seq, message)
            data = buffer.getvalue()
            buffer.seek(0)
            buffer.truncate(0)
            self._append(impl, connections, data, 1)

    def publish_records(self, impl, records: np.ndarray):
        """Messages serialized as numpy records (``length`` prefix first, header ``seq`` to fill), in one piece."""
        with self._impl_lock(impl), self._lock:
            connections = self._open_connections(impl)
            if not connections or not len(records):
                return
            records["seq"] = np.arange(impl.seq + 1, impl.seq + 1 + len(records))
            impl.seq += len(records)
            self._append(impl, connections, records.tobytes(), len(records))

    @staticmethod
    def _impl_lock(impl):
        """The publisher's lock; a publisher rospy has closed (its shutdown runs in another thread, when the master
        hands the node's name to a new node) has none left, and takes no messages, as rospy's own publish."""
        return impl.publock or contextlib.nullcontext()

    @staticmethod
    def _open_connections(impl) -> list:
        return [] if impl.closed else [connection for connection in impl.connections if not connection.done]

    def _append(self, impl, connections: list, data: bytes, count: int):
        ids = [number for number in (self._id(connection, impl) for connection in connections) if number is not None]
        if not ids:
            return
        impl.message_data_sent += len(data)
        if not self._batch:
            self._batch_started = time.monotonic()
        self._batch += DATA_HEADER.pack(DATA, len(ids), len(data))
        self._batch += struct.pack(f"<{len(ids)}I", *ids)
        self._batch += data
        for connection in connections:
            connection.stat_bytes += len(data)
            connection.stat_num_msg += count

    def _id(self, connection, impl) -> Optional[int]:
        """The writer's number for ``connection``; None while rospy is closing it (it closes the socket before
        it marks the connection done, so a new subscriber that leaves at once has no descriptor to hand over)."""
        known = self._ids.get(connection)
        if known is not None:
            return known[0]
        sock = connection.socket
        descriptor = -1 if sock is None else sock.fileno()
        if descriptor < 0:
            return None
        number = self._next_id
        # The descriptor travels with its OPEN frame, so everything batched before it goes first.
        self._send_batch()
        try:
            socket.send_fds(self._channel, [ID.pack(OPEN, number)], [descriptor])
        except OSError as error:
            if error.errno == errno.EBADF:  # closed by rospy since fileno(): that subscriber has gone
                return None
            self._failure = self._failure or error
        self._next_id += 1
        self._ids[connection] = (number, impl)
        self._connections[number] = connection
        return number

    def forget(self, connections: List[object]):
        """rospy closed these connections (a publisher unregistered): the writer drops its copies."""
        with self._lock:
            for connection in connections:
                known = self._ids.pop(connection, None)
                if known is not None:
                    del self._connections[known[0]]
                    self._batch += ID.pack(CLOSE, known[0])

    def flush(self, wait: bool = False):
        """Hand the batch to the writer, and now and then close in rospy the connections it found dead (a
        departed subscriber is no hurry; a read at every pass would be a system call per pass).

        With ``wait``, a young small batch waits for the next pass: each hand-off wakes the writer, which cost
        about 50 us of the loop when the loop ran flat out (profile), so passes closer than COALESCE_SECONDS of
        wall time share one. The loop flushes without ``wait`` before it sleeps or pauses."""
        with self._lock:
            now = time.monotonic()
            if wait and now - self._batch_started < COALESCE_SECONDS and len(self._batch) < _COALESCE_BYTES:
                return
            self._send_batch()
            self._raise_failure()
            if now >= self._next_answers_read:
                self._next_answers_read = now + _ANSWERS_READ_SECONDS
                self._read_answers(None)

    def sync(self):
        """Flush and wait until the writer has written everything (lockstep answers after all output)."""
        with self._lock:
            token = self._next_token
            self._next_token += 1
            self._batch += ID.pack(SYNC, token)
            self._send_batch()
            self._raise_failure()
            self._read_answers(token)

    def _send_batch(self):
        """Hand the batch over. A failure is kept for the loop's next flush to raise: raised inside a plugin's
        publish, it would be taken for that plugin's failure."""
        if self._batch and self._failure is None:
            try:
                self._channel.sendall(self._batch)
            except OSError as error:
                self._failure = error
        self._batch.clear()

    def _raise_failure(self):
        if self._failure is not None:
            raise WriterStopped(f"the writer process stopped ({self._failure}, exit status "
                                f"{self.process.poll()}); nothing more can be published")

    def _read_answers(self, token: Optional[int]):
        """Read the writer's answers; with a token, until that SYNCED arrives."""
        while True:
            try:
                data = self._channel.recv(4096, 0 if token is not None else socket.MSG_DONTWAIT)
            except BlockingIOError:
                return
            if not data:
                raise WriterStopped(f"the writer process stopped (exit status {self.process.poll()})")
            self._answers += data
            usable = len(self._answers) - len(self._answers) % ID.size
            synced = False
            for kind, number in ID.iter_unpack(bytes(self._answers[:usable])):
                if kind == DEAD:
                    self._close_dead(number)
                elif kind == SLOW:
                    self._report_slow(number)
                elif kind == SYNCED and number == token:
                    synced = True
            del self._answers[:usable]
            if synced:
                return

    def _report_slow(self, number: int):
        connection = self._connections.get(number)
        if connection is not None:
            rospy.logwarn(f"{connection.endpoint_id} does not keep up with {connection.name}: the simulator drops "
                          "its oldest messages for it rather than wait (as a roscpp publisher's queue does); said "
                          "once per subscriber")

    def _close_dead(self, number: int):
        connection = self._connections.pop(number, None)
        if connection is None:
            return
        _, impl = self._ids.pop(connection)
        with self._impl_lock(impl):
            connection.close()  # rospy's cleanup callback removes it from the topic, as after a failed write

    def close(self):
        self._channel.close()  # the writer ends at end of file
        try:
            self.process.wait(_STOP_SECONDS)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


_publishing: Optional[LoopPublishing] = None


def start() -> LoopPublishing:
    """Start the writer process; loop publishers made after this write through it."""
    global _publishing
    _publishing = LoopPublishing()
    return _publishing


def stop():
    global _publishing
    if _publishing is not None:
        _publishing.close()
        _publishing = None


class LoopPublisher:
    """A publisher the loop thread writes to synchronously: through the writer process once it runs, else
    directly (queue_size=None: rospy's queued publishers hand each message to a thread, and that GIL hand-off
    costs more than a physics step)."""

    def __init__(self, name: str, message_type):
        with warnings.catch_warnings():  # rospy warns about queue_size=None, deliberate here
            warnings.simplefilter("ignore", SyntaxWarning)
            self._publisher = rospy.Publisher(name, message_type, queue_size=None)
        self._publishing = _publishing
        self.resolved_name = self._publisher.resolved_name
        self.data_class = message_type

    def publish(self, message):
        if self._publishing is None:
            self._publisher.publish(message)
        else:
            self._publishing.publish(self._publisher.impl, message)

    def publish_records(self, records: np.ndarray):
        """Messages already serialized as numpy records (``messages.imu_records``), numbered and sent at once."""
        if self._publishing is None:
            for record in records:
                self._publisher.publish(self.data_class().deserialize(record.tobytes()[4:]))
        else:
            self._publishing.publish_records(self._publisher.impl, records)

    def get_num_connections(self) -> int:
        return self._publisher.get_num_connections()

    def unregister(self):
        impl = self._publisher.impl
        connections = list(impl.connections) if impl is not None else []
        self._publisher.unregister()
        if self._publishing is not None:
            self._publishing.forget([connection for connection in connections if connection.done])

