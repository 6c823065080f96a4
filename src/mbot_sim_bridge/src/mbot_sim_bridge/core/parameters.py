"""What the simulation reads from the ROS parameter server, handed in rather than fetched: ``Parameters``
holds them as a tree of dicts (tests, the demo); the ROS node passes ``ros_parameters.RosParameters``, which
asks the master. Names are absolute ("/mbot/joint_limits").
"""
from typing import Any, Optional

_MISSING = object()


class Parameters:
    def __init__(self, tree: Optional[dict] = None):
        self.tree = tree or {}

    def get(self, name: str, default: Any = None) -> Any:
        """The value of the absolute parameter ``name`` (a dict for a namespace), or ``default``."""
        node = self.tree
        for part in _parts(name):
            if not isinstance(node, dict) or part not in node:
                return default
            node = node[part]
        return node

    def has(self, name: str) -> bool:
        return self.get(name, _MISSING) is not _MISSING

    def search(self, namespace: str, key: str) -> Optional[str]:
        """NodeHandle::searchParam from ``namespace``: the nearest ``key`` found going up towards the root (an
        absolute ``key`` stands as it is), or None."""
        if key.startswith("/"):
            return key if self.has(key) else None
        parts = _parts(namespace)
        for depth in range(len(parts), -1, -1):
            name = "/" + "/".join(parts[:depth] + _parts(key))
            if self.has(name):
                return name
        return None


def absolute_name(namespace: str, name: str) -> str:
    """A parameter name as a NodeHandle in ``namespace`` resolves it: absolute names stand."""
    return name if name.startswith("/") else "/" + "/".join(_parts(namespace) + _parts(name))


def _parts(name: str):
    return [part for part in name.split("/") if part]
