"""Launch and rostest files named in a spec: resolved as roslaunch resolves them, with the arguments they take."""
import os

import roslaunch
import roslaunch.arg_dump
import roslaunch.rlutil

from .spec import SpecError


def resolve(reference: str, folder: str, where: str):
    """``PACKAGE FILE`` (as roslaunch and rostest take them) or a path relative to ``folder``; returns the file's
    absolute path and the arguments it declares."""
    words = reference.split()
    try:
        if len(words) == 2 and not os.path.exists(os.path.join(folder, reference)):
            path = roslaunch.rlutil.resolve_launch_arguments(words)[0]
        else:
            path = os.path.join(folder, reference)
            if not os.path.isfile(path):
                raise SpecError(f"{where}: no such launch file: {path}")
        return os.path.abspath(path), tuple(roslaunch.arg_dump.get_args([path]))
    except roslaunch.RLException as error:
        raise SpecError(f"{where}: {' '.join(str(error).split())}") from None
