"""xacro as Noetic runs it, on PyPI's xacro 2.x: ``process_file`` and ``main`` with 2.x's language (Noetic's 1.14
features: ``xacro.load_yaml``, dotted access, ``!degrees``), ``$(find pkg)`` over ROS_PACKAGE_PATH (the
``ament_index_python`` shim beside this package), and one thing 2.x dropped: a macro called without the
``xacro:`` prefix (``<wheel .../>`` for ``<xacro:wheel .../>``), which Noetic's xacro still expands with a
deprecation warning and which the course's descriptions use.

Import this instead of ``xacro`` (``import xacro_noetic as xacro``); ``$(find xacro)/xacro`` runs its ``main``.
"""
import xacro
from xacro.color import warning

_expand_macro_call = xacro.handle_macro_call
_warned = set()


def _is_macro(name, macros, symbols) -> bool:
    try:
        xacro.resolve_macro(name, macros, symbols)
    except KeyError:
        return False
    return True


def _handle_macro_call(node, macros, symbols):
    """2.x's macro call, after naming an unprefixed call of a known macro as Noetic's xacro does."""
    if not node.tagName.startswith("xacro:") and _is_macro(node.tagName, macros, symbols):
        if node.tagName not in _warned:
            _warned.add(node.tagName)
            warning(f"deprecated: xacro tags should be prepended with 'xacro' xml namespace: <{node.tagName}>")
        node.tagName = node.nodeName = "xacro:" + node.tagName
    return _expand_macro_call(node, macros, symbols)


# xacro's evaluator looks the function up in its module at each element, so this one takes its place there.
xacro.handle_macro_call = _handle_macro_call
process_file = xacro.process_file
main = xacro.main
