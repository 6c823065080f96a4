"""Every test function of the workspace asserts something: a test that only runs code passes whatever the code
does.

A test asserts when its body has an assert statement, a raise, a self.assert*/self.fail call, pytest.raises/warns/
fail, or calls a function that does (followed transitively) defined in its own module or imported by name from a
module under a test/ or tests/ folder. wait_until and wait_for count: they raise AssertionError naming the
condition when it does not come true in time."""
import ast
import pathlib

from ros_processes import TESTS

WORKSPACE = pathlib.Path(TESTS).parent
SKIPPED_FOLDERS = {".venv", "build", "devel", "third_party", "__pycache__"}
WAITS = {"wait_until", "wait_for"}


def modules_under_test_folders():
    """Every .py under a test/ or tests/ folder of the workspace: test files and the helpers they import."""
    return [path for folder in ("src", "tests") for path in (WORKSPACE / folder).rglob("*.py")
            if {"test", "tests"} & set(path.relative_to(WORKSPACE).parts)
            and not SKIPPED_FOLDERS & set(path.relative_to(WORKSPACE).parts)]


def called_names(node):
    for child in ast.walk(node):
        if isinstance(child, ast.Call):
            function = child.func
            yield function.attr if isinstance(function, ast.Attribute) else getattr(function, "id", "")


def asserts_directly(node):
    if any(isinstance(child, (ast.Assert, ast.Raise)) for child in ast.walk(node)):
        return True
    return any(name.startswith(("assert", "fail")) or name in {"raises", "warns"} | WAITS
               for name in called_names(node))


def functions_by_module(trees):
    """{module name: {function name: node}} over every function and method of ``trees``."""
    found = {}
    for path, tree in trees.items():
        found.setdefault(path.stem, {}).update(
            {node.name: node for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))})
    return found


def visible_functions(tree, module, functions):
    visible = dict(functions.get(module, {}))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            source = functions.get(node.module.split(".")[-1], {})
            visible.update({alias.asname or alias.name: source[alias.name] for alias in node.names
                            if alias.name in source})
    return visible


def asserts(node, visible, seen=()):
    return asserts_directly(node) or any(
        name in visible and name not in seen and asserts(visible[name], visible, seen + (name,))
        for name in called_names(node))


def functions_without_assertions(trees):
    functions = functions_by_module(trees)
    missing = []
    for path, tree in sorted(trees.items()):
        if not path.name.startswith("test_"):
            continue
        visible = visible_functions(tree, path.stem, functions)
        missing += [f"{path}:{node.lineno} {node.name}" for node in ast.walk(tree)
                    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name.startswith("test")
                    and not asserts(node, visible)]
    return missing


def test_every_test_function_asserts():
    trees = {path: ast.parse(path.read_text(), str(path)) for path in modules_under_test_folders()}
    assert len(trees) > 100
    missing = functions_without_assertions(trees)
    assert not missing, "test functions without an assertion:\n" + "\n".join(missing)


def test_the_check_follows_helpers_and_finds_a_test_without_one():
    helper = pathlib.Path("helpers.py")
    trees = {helper: ast.parse("def expect_two(value):\n    assert value == 2\n"
                               "def show(value):\n    print(value)\n"),
             pathlib.Path("test_x.py"): ast.parse(
                 "from helpers import expect_two, show\n"
                 "def check(value):\n    expect_two(value)\n"
                 "def test_through_two_helpers():\n    check(2)\n"
                 "def test_waits():\n    wait_until(lambda: True, 1, 'x')\n"
                 "class T:\n    def test_unittest(self):\n        self.assertEqual(1, 1)\n"
                 "def test_prints_only():\n    show(2)\n")}
    assert functions_without_assertions(trees) == ["test_x.py:11 test_prints_only"]
