"""A private X server for GUI tests, and screenshots of it.

Xvfb picks a free display number itself (``-displayfd``) and writes it back once it accepts clients, so
there is neither a guessed number nor a wait for readiness. Screenshots go through ``xwd`` and ImageMagick.
"""
import os
import select
import subprocess

import numpy as np
from PIL import Image

CONVERT = "/usr/bin/convert"  # ImageMagick's, by full path: another program of that name may come first on PATH


class Xvfb:
    """``with Xvfb(log_path) as server:`` runs Xvfb on ``server.display`` (":N") until the block ends."""

    def __init__(self, log_path, screen="1280x800x24", timeout=15.0):
        self.log_path = log_path
        self.screen = screen
        self.timeout = timeout
        self.display = None
        self._process = None

    def __enter__(self):
        read_end, write_end = os.pipe()
        try:
            with open(self.log_path, "w") as log:
                # -br: a black root window, so an empty screen is one flat colour.
                self._process = subprocess.Popen(
                    ["Xvfb", "-displayfd", str(write_end), "-screen", "0", self.screen, "-nolisten", "tcp", "-br"],
                    pass_fds=(write_end,), stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                    start_new_session=True)
            os.close(write_end)
            write_end = None
            self.display = ":" + self._read_display_number(read_end)
        except BaseException:
            self._stop()
            raise
        finally:
            os.close(read_end)
            if write_end is not None:
                os.close(write_end)
        return self

    def __exit__(self, *exc_info):
        self._stop()

    def environment(self, base, **more) -> dict:
        """``base`` with DISPLAY on this server and Mesa's software OpenGL on one thread: llvmpipe's rasteriser
        threads cost more CPU to keep in step than they save on these tests' small or infrequent frames."""
        return dict(base, DISPLAY=self.display, LIBGL_ALWAYS_SOFTWARE="1", LP_NUM_THREADS="1", **more)

    def screenshot(self, png_path, attempts=3) -> np.ndarray:
        """Save the whole screen as a PNG; returns it as an (height, width, 3) uint8 RGB array.

        xwd reads every window whose visual differs from the root's (an OpenGL view) on its own, so a window
        destroyed meanwhile, as happens while an application starts, fails the read: it is tried again.
        """
        for _ in range(attempts):
            xwd = subprocess.Popen(["xwd", "-root", "-silent", "-display", self.display], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE)
            try:
                convert = subprocess.run([CONVERT, "xwd:-", f"png:{png_path}"], stdin=xwd.stdout,
                                         capture_output=True, timeout=self.timeout)
            finally:
                xwd.stdout.close()
                xwd_error = xwd.communicate(timeout=self.timeout)[1]
            if xwd.returncode == 0 and convert.returncode == 0:
                with Image.open(png_path) as image:
                    return np.asarray(image.convert("RGB"))
        raise RuntimeError(f"screenshot of {self.display} failed {attempts} times, last: "
                           f"{xwd_error.decode()}{convert.stderr.decode()}")

    def _read_display_number(self, read_end) -> str:
        text = b""
        while not text.endswith(b"\n"):
            ready, _, _ = select.select([read_end], [], [], self.timeout)
            chunk = os.read(read_end, 16) if ready else b""
            if not chunk:
                raise RuntimeError(f"Xvfb did not report a display within {self.timeout:.0f} s (exit code "
                                   f"{self._process.poll()}); see {self.log_path}")
            text += chunk
        return text.decode().strip()

    def _stop(self):
        if self._process is not None and self._process.poll() is None:
            self._process.terminate()
            try:
                self._process.wait(timeout=self.timeout)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
