"""No import cycle anywhere in the mbot_sim_bridge package: every import counts, those under ``if TYPE_CHECKING``
and inside functions included, so a module can be changed and tested with only what it imports below it."""
import ast
import os
from typing import Dict, List, Set

PACKAGE = "mbot_sim_bridge"
ROOT = os.path.join(os.path.dirname(__file__), "..", "..", "src", PACKAGE)


def _modules() -> Dict[str, str]:
    """Module name -> file, for every module and package of the package."""
    modules = {}
    for folder, _, names in os.walk(ROOT):
        for name in names:
            if name.endswith(".py"):
                parts = [PACKAGE, *os.path.relpath(os.path.join(folder, name), ROOT)[:-len(".py")].split(os.sep)]
                modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = os.path.join(folder, name)
    return modules


def import_graph() -> Dict[str, Set[str]]:
    """Module -> the package's modules it imports (``from package import module`` names the module)."""
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        package = name if path.endswith("__init__.py") else name.rpartition(".")[0]
        imported = set()
        for node in ast.walk(ast.parse(open(path).read(), path)):
            if isinstance(node, ast.Import):
                imported.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")
                    base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
                imported.update(f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base
                                for alias in node.names)
        graph[name] = {module for module in imported if module in modules and module != name}
    return graph


def cycles(graph: Dict[str, Set[str]]) -> List[List[str]]:
    """The strongly connected groups of more than one module (Tarjan's algorithm, iterative)."""
    index: Dict[str, int] = {}
    low: Dict[str, int] = {}
    stack: List[str] = []
    on_stack: Set[str] = set()
    groups = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            successor = next(successors, None)
            if successor is not None:
                if successor not in index:
                    index[successor] = low[successor] = len(index)
                    stack.append(successor)
                    on_stack.add(successor)
                    work.append((successor, iter(sorted(graph[successor]))))
                elif successor in on_stack:
                    low[node] = min(low[node], index[successor])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.append(member)
                    if member == node:
                        break
                if len(group) > 1:
                    groups.append(sorted(group))
    return groups


def test_the_package_has_no_import_cycle():
    graph = import_graph()
    assert {"mbot_sim_bridge.core.simulation", "mbot_sim_bridge.core.drives.diff_drive",
            "mbot_sim_bridge.plugins.registry"} <= set(graph)
    assert cycles(graph) == []


def test_a_type_only_import_closes_a_cycle():
    graph = import_graph()
    assert "mbot_sim_bridge.core.cameras.render_scene" in graph["mbot_sim_bridge.core.plugin"]  # under TYPE_CHECKING
    graph["mbot_sim_bridge.core.cameras.render_scene"].add("mbot_sim_bridge.core.plugin")
    assert cycles(graph) == [["mbot_sim_bridge.core.cameras.render_scene", "mbot_sim_bridge.core.plugin"]]
