"""Subscribers whose pending messages can be waited for: the ordering guarantee of lockstep stepping.

rospy reads each connection in a thread of its own and calls the callbacks there, so a message published to
the bridge just before a step request (which arrives on another connection) may still be in the socket, or
half-way through its callback, when the request is served. ``drain`` waits until every tracked connection is
idle: no unread bytes in the socket or in rospy's read buffer, no parse under way, and as many callbacks
finished as messages parsed. rospy has no hook for this, so the connection's parser is wrapped to count what
it parses (rospy 1.15's TCPROS transport: ``protocol.read_messages`` into an empty queue, then callbacks),
and rospy's ``recv_buff`` is wrapped so that a tracked connection's reader waits for bytes without taking
them and counts as parsing before it takes them: a reader that had taken bytes and then waited for the GIL
(milliseconds under load) looked idle, and a command published before a step request was applied after it.
On one host a publisher's synchronous ``publish`` on a TCP_NODELAY connection (which these subscribers ask
for) has put its bytes in the bridge's socket before it returns, so a node that publishes synchronously
(``queue_size=None``) and then calls the step service sees its message applied before the first step.
"""
import select
import threading
import time
from typing import Callable, Iterable, List, Tuple

import rospy
import rospy.impl.tcpros_base as tcpros_base

# Idle is checked twice this far apart, for bytes on their way into the socket at the first look.
_SETTLE_SECONDS = 0.002


class TrackedSubscriber:
    """A rospy.Subscriber that knows whether a message that reached it is still on its way to the callback."""

    def __init__(self, name: str, message_type, callback: Callable, queue_size=1):
        self._callback = callback
        self._lock = threading.Lock()
        # Connections (their header dict's id) in the middle of a parse, and parsed messages (ids) whose
        # callback has not finished.
        self._parsing = set()
        self._pending = set()
        # TCP_NODELAY on the publisher's side: with Nagle's algorithm a small message may wait there for an
        # acknowledgement (up to 40 ms on Linux) after publish() has returned.
        self.subscriber = rospy.Subscriber(name, message_type, self._on_message, queue_size=queue_size,
                                           tcp_nodelay=True)
        _TRACKED.append(self)

    def _on_message(self, message):
        try:
            self._callback(message)
        finally:
            with self._lock:
                self._pending.discard(id(message))

    def _mark_parsing(self, key) -> None:
        with self._lock:
            self._parsing.add(key)

    def _unmark_parsing(self, key) -> None:
        with self._lock:
            self._parsing.discard(key)

    def _watch(self, connection):
        """Note what this connection's parser turns into messages (wrapped once per subscriber)."""
        protocol = connection.protocol
        if not hasattr(protocol, "trackers"):
            protocol.trackers = set()
        if self in protocol.trackers:
            return
        protocol.trackers.add(self)
        key, parse = id(connection.header), protocol.read_messages

        def read_messages(buffer, queue, sock):
            self._mark_parsing(key)
            try:
                parse(buffer, queue, sock)
            finally:
                with self._lock:
                    self._pending.update(id(message) for message in queue)
                    self._parsing.discard(key)
        protocol.read_messages = read_messages

    def idle(self) -> bool:
        for connection in list(self.subscriber.impl.connections if self.subscriber.impl else ()):
            sock = connection.socket
            if sock is None or connection.header is None:
                continue
            self._watch(connection)
            try:
                readable = readable_within(sock, 0)
            except (ValueError, OSError):  # closed under us: nothing more will come from it
                continue
            with self._lock:
                busy = id(connection.header) in self._parsing
            if readable or busy or connection.read_buff.tell() > 0:
                return False
        with self._lock:
            return not self._pending

    def get_num_connections(self) -> int:
        return self.subscriber.get_num_connections()

    def unregister(self):
        self.subscriber.unregister()
        if self in _TRACKED:
            _TRACKED.remove(self)


def readable_within(sock, timeout_ms) -> bool:
    """Whether ``sock`` has bytes to read (or has been closed) within ``timeout_ms`` (None: wait for it). poll,
    not select: select refuses descriptors past 1024, which a process with many connections has."""
    waiting = select.poll()
    waiting.register(sock, select.POLLIN | select.POLLPRI)
    return bool(waiting.poll(timeout_ms))


_TRACKED: List[TrackedSubscriber] = []
_ROSPY_RECV_BUFF = tcpros_base.recv_buff


def _trackers_of(sock) -> List[Tuple[TrackedSubscriber, int]]:
    """The tracked subscribers reading from ``sock``, each with its key for the connection."""
    found = []
    for subscriber in list(_TRACKED):
        impl = subscriber.subscriber.impl
        for connection in list(impl.connections if impl else ()):
            if connection.socket is sock and connection.header is not None:
                subscriber._watch(connection)
                found.append((subscriber, id(connection.header)))
    return found


def _recv_buff(sock, buffer, size):
    """rospy's recv_buff; on a tracked connection it first waits until bytes are there, without taking them
    (the GIL is free meanwhile), then marks the connection as parsing, then takes them. The read_messages
    wrapper of ``_watch`` clears the mark once they are parsed."""
    trackers = _trackers_of(sock)
    if trackers:
        try:
            readable_within(sock, None)
        except (ValueError, OSError):
            pass  # closed meanwhile: rospy's own read reports it
        for subscriber, key in trackers:
            subscriber._mark_parsing(key)
    try:
        return _ROSPY_RECV_BUFF(sock, buffer, size)
    except BaseException:
        for subscriber, key in trackers:
            subscriber._unmark_parsing(key)
        raise


# rospy's TCPROS transport calls the module's recv_buff by name for every read of a subscribed connection.
tcpros_base.recv_buff = _recv_buff


def drain(subscribers: Iterable[TrackedSubscriber] = None, timeout: float = 5.0) -> bool:
    """Wait until every tracked subscriber (or those given) has handled what reached it; False on timeout."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        current = list(_TRACKED if subscribers is None else subscribers)
        if all(subscriber.idle() for subscriber in current):
            time.sleep(_SETTLE_SECONDS)
            if all(subscriber.idle() for subscriber in current):
                return True
        time.sleep(_SETTLE_SECONDS)
    return False
