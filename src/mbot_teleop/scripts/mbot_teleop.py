#!/usr/bin/env python3
"""Keyboard teleop for the mbot; the code lives in the mbot_teleop package."""

import os
import sys

# Python puts this file's directory first on sys.path, and the file is named like the
# package: drop that entry so the import below finds the package, not this script.
_HERE = os.path.dirname(os.path.realpath(sys.argv[0]))
sys.path[:] = [path for path in sys.path if os.path.realpath(path or os.curdir) != _HERE]

from mbot_teleop.node import main  # noqa: E402  (needs the sys.path fix above)

if __name__ == '__main__':
    sys.exit(main())
