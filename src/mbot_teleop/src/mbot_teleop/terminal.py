"""Single keys from a terminal: raw mode and a select() poll, as the course reads them."""

import contextlib
import errno
import os
import select
import termios
import tty


@contextlib.contextmanager
def raw_mode(fd):
    """Keep the terminal on fd in raw mode inside the block; restore its mode on any exit.

    Raw mode hands over each key at once, unechoed, and CTRL-C as a byte instead
    of SIGINT. Output processing stays on, so printed lines and rospy's log lines
    still start at column 0.
    """
    saved = termios.tcgetattr(fd)
    try:
        tty.setraw(fd)
        mode = termios.tcgetattr(fd)
        mode[tty.OFLAG] |= termios.OPOST
        termios.tcsetattr(fd, termios.TCSANOW, mode)
        yield
    finally:
        try:
            termios.tcsetattr(fd, termios.TCSADRAIN, saved)
        except termios.error as error:
            # A terminal that has gone away has no mode left to restore.
            if error.args[0] != errno.EIO:
                raise


def read_key(fd, timeout):
    """Return the next key on fd, or '' if none comes within timeout seconds.

    A key is one byte, so arrows and non-ASCII keys arrive as several unbound
    keys. os.read takes exactly that byte: a buffered sys.stdin.read(1) would
    swallow the keys behind it, where select() no longer sees them.
    Raises EOFError once the terminal is gone.
    """
    ready, _, _ = select.select([fd], [], [], timeout)
    if not ready:
        return ''
    try:
        data = os.read(fd, 1)
    except OSError as error:
        # A pseudo-terminal whose master side closed (terminal window shut) reads EIO.
        if error.errno == errno.EIO:
            raise EOFError('terminal closed') from error
        raise
    if not data:
        raise EOFError('terminal closed')
    return data.decode('latin-1')
