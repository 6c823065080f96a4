"""Raw mode and the key poll, on a real pseudo-terminal."""

import os
import termios
import tty

import pytest

from mbot_teleop.terminal import raw_mode, read_key


@pytest.fixture
def pty_pair():
    master, slave = os.openpty()
    yield master, slave
    for fd in (master, slave):
        try:
            os.close(fd)
        except OSError:
            pass  # closed by the test


def test_raw_mode_inside_and_restored_after(pty_pair):
    _, slave = pty_pair
    before = termios.tcgetattr(slave)
    with raw_mode(slave):
        mode = termios.tcgetattr(slave)
        assert not mode[tty.LFLAG] & (termios.ICANON | termios.ECHO | termios.ISIG)
        assert mode[tty.OFLAG] & termios.OPOST
    assert termios.tcgetattr(slave) == before


@pytest.mark.parametrize('error', [RuntimeError, KeyboardInterrupt])
def test_raw_mode_restored_on_error(pty_pair, error):
    _, slave = pty_pair
    before = termios.tcgetattr(slave)
    with pytest.raises(error):
        with raw_mode(slave):
            raise error()
    assert termios.tcgetattr(slave) == before


def test_keys_come_one_per_read_and_none_after(pty_pair):
    master, slave = pty_pair
    with raw_mode(slave):
        os.write(master, b'i,\x03')
        assert [read_key(slave, 1.0) for _ in range(3)] == ['i', ',', '\x03']
        assert read_key(slave, 0.01) == ''


def test_closed_terminal_reads_as_eof(pty_pair):
    master, slave = pty_pair
    with raw_mode(slave):
        os.close(master)
        with pytest.raises(EOFError):
            read_key(slave, 1.0)
