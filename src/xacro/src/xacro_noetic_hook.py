"""``import xacro`` in the workspace's venv gives xacro as Noetic runs it (``xacro_noetic``), and so does the
``xacro`` on the PATH: that is PyPI's own console script (``from xacro import main``), which any ``pip install``
of xacro writes again, so only the module can carry Noetic's behaviour.

``./mbot setup`` writes ``xacro_noetic.pth`` into the venv's site-packages; it imports this module at every
interpreter start, as setuptools' ``distutils-precedence.pth`` does its distutils shim. Nothing is imported here
until a program imports xacro: loading it at each start would slow every node down.
"""
import sys
from importlib.machinery import PathFinder


class XacroAsNoetic:
    """Finds PyPI's xacro on sys.path as Python would, and has ``xacro_noetic`` adapt it once it has loaded."""

    @staticmethod
    def find_spec(name, path=None, target=None):
        if name != "xacro":
            return None
        spec = PathFinder.find_spec(name, path)
        if spec is not None and spec.loader is not None:
            load = spec.loader.exec_module

            def load_then_adapt(module):
                load(module)
                import xacro_noetic  # noqa: F401 - adapts sys.modules["xacro"], the module just loaded

            spec.loader.exec_module = load_then_adapt
        return spec


sys.meta_path.insert(0, XacroAsNoetic)
