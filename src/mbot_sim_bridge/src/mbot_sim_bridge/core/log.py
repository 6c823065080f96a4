"""Logging for the core, and where PyBullet's own prints go.

Core modules log to children of the stdlib logger ``rosout``: under rospy that logger reaches the console
and /rosout, under pytest it reaches ``caplog``. ``warn_once`` keeps a bad input from flooding the log.
"""
import contextlib
import logging
import os
import sys
import threading
from typing import Hashable, Optional

_warned = set()
_warned_lock = threading.Lock()


def get_logger(module_name: str) -> logging.Logger:
    """``get_logger(__name__)`` -> ``rosout.mbot_sim_bridge.core.<module>``."""
    return logging.getLogger("rosout." + module_name)


def log_once(logger: logging.Logger, level: int, message: str, key: Optional[Hashable] = None) -> None:
    """Log ``message`` at ``level`` the first time this exact text (or ``key``, for a message that names one of
    many places of the same problem) is seen in the process."""
    seen = message if key is None else key
    with _warned_lock:
        if seen in _warned:
            return
        _warned.add(seen)
    logger.log(level, message)


def warn_once(logger: logging.Logger, message: str, key: Optional[Hashable] = None) -> None:
    log_once(logger, logging.WARNING, message, key)


def info_once(logger: logging.Logger, message: str) -> None:
    log_once(logger, logging.INFO, message)


def forget_warnings() -> None:
    """Let every warning be logged again (tests use this to check a warning appears)."""
    with _warned_lock:
        _warned.clear()


@contextlib.contextmanager
def c_stdout_to(stream):
    """File descriptor 1, where PyBullet's C code prints (past ``sys.stdout``), goes to ``stream`` (a file open
    for writing) meanwhile."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(stream.fileno(), 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
