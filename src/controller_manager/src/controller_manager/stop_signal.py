"""The spawner's and unspawner's stop request: SIGINT or SIGTERM set an Event the main thread waits on."""
import signal
import threading


def stop_on_signals() -> threading.Event:
    """An Event that SIGINT and SIGTERM set.

    Python runs a signal handler in the main thread, and it may run while that thread is inside the same Event's
    ``wait`` holding the Event's lock: ``Event.set`` there waits for that lock for ever (an unspawner hung so in
    the suite). The handler therefore leaves the ``set`` to a short-lived thread of its own.
    """
    stop = threading.Event()

    def request_stop(*_):
        threading.Thread(target=stop.set, name="stop request", daemon=True).start()

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, request_stop)
    return stop
