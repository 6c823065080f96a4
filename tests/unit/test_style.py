"""One Python style across the workspace: ruff (configured in ruff.toml) passes, and log calls get one finished
message each (an f-string), not a format with arguments."""
import ast
import pathlib
import subprocess
import sys

from ros_processes import TESTS

WORKSPACE = pathlib.Path(TESTS).parent
LOG_METHODS = {"logdebug", "loginfo", "logwarn", "logerr", "logfatal", "debug", "info", "warning", "error",
               "critical", "exception"}
LOGGERS = {"rospy", "_log", "_logger", "logging"}


def python_files():
    return [path for folder in ("src", "tests") for path in (WORKSPACE / folder).rglob("*.py")
            if "__pycache__" not in path.parts]


def log_calls_with_format_arguments(tree: ast.AST):
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and isinstance(node.func.value, ast.Name) and node.func.value.id in LOGGERS):
            continue
        method = node.func.attr
        base = method.split("_")[0]
        if base not in LOG_METHODS:
            continue
        message_index = 1 if method.endswith("_throttle") else 0
        if len(node.args) > message_index + 1:
            yield node.lineno, method


def test_ruff_passes():
    result = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", str(WORKSPACE)],
                            capture_output=True, text=True, cwd=WORKSPACE)
    assert result.returncode == 0, result.stdout + result.stderr


def test_log_calls_get_one_finished_message():
    found = [f"{path.relative_to(WORKSPACE)}:{line}: {method}(format, arguments...)"
             for path in python_files()
             for line, method in log_calls_with_format_arguments(ast.parse(path.read_text(), str(path)))]
    assert not found, "log calls with format arguments (write one f-string instead):\n" + "\n".join(found)


def test_the_log_call_check_finds_format_arguments():
    bad = ast.parse('rospy.loginfo("%s spawned", name)\n_logger.warning("x %d", 1)\n'
                    'rospy.logwarn_throttle(5, "late by %f", lag)\nrospy.loginfo(f"{name} spawned")\n')
    assert [method for _, method in log_calls_with_format_arguments(bad)] == ["loginfo", "warning", "logwarn_throttle"]
