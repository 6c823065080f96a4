"""What every test of the workspace shares: the pure-core fixtures (no ROS master), and rostest files collected as
test items, so that one runner (pytest, with pytest-xdist's workers) schedules and filters everything.

A ``.test`` file becomes one item named after the file; it runs ``rostest --text`` and reports the number of test
cases it ran as the junit properties ``rostest_tests`` and ``rostest_failed`` (``tests/run_all.py`` counts those).
The Python files a ``.test`` file runs as test nodes are not collected by pytest.
"""
import logging
import re
import subprocess
import sys
import tempfile
from pathlib import Path
from xml.etree import ElementTree

import pytest
from mbot_sim_bridge.core.log import forget_warnings

ROOT = Path(__file__).resolve().parent
# pytest keeps the test modules it rewrote for their asserts (and the plugin packages it rewrites) in __pycache__,
# as Python keeps bytecode, unless writing bytecode is off (PYTHONDONTWRITEBYTECODE, common in containers): then
# every worker rewrote every module at every run, half the CPU of collecting the suite. ./mbot setup collects once
# to write them; a changed module is written again by the run that meets it.
sys.dont_write_bytecode = False
ROSTEST_GLOBS = ("src/*/test/*.test", "tests/*.test")
# The longest rostest file takes under a minute; one that hangs is stopped and counted as failed.
ROSTEST_TIMEOUT_SECONDS = 600


@pytest.fixture
def client():
    """A PyBullet physics client of the test's own, in DIRECT mode."""
    # Imported here: PyBullet prints its build time on import, and the runner's own process needs none of it.
    import pybullet
    from pybullet_utils.bullet_client import BulletClient
    bullet = BulletClient(connection_mode=pybullet.DIRECT)
    yield bullet
    bullet.disconnect()


@pytest.fixture(autouse=True)
def fresh_warnings():
    """Each test sees its own once-only warnings, and the bridge's log level as it starts (a robot's
    rosDebugLevel tag changes it for the whole process)."""
    forget_warnings()
    logger = logging.getLogger("rosout.mbot_sim_bridge")
    level = logger.level
    yield
    logger.setLevel(level)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """A test's ``figure: ...`` output lines (its measurements) become junit properties, which the runner prints
    after the run: a worker's output would otherwise be seen only when the test fails."""
    report = (yield).get_result()
    figures = [line.split("figure: ", 1)[1] for title, content in report.sections if title.endswith(report.when)
               for line in content.splitlines() if line.startswith("figure: ")]
    # The junit report takes a test's properties from its teardown report, which copies the item's.
    (item.user_properties if report.when != "teardown" else report.user_properties).extend(
        ("figure", figure) for figure in figures)


def rostest_files():
    return sorted(path for pattern in ROSTEST_GLOBS for path in ROOT.glob(pattern))


def _rostest_nodes():
    """The Python files that ``.test`` files run as test nodes (found under the test folders by their type)."""
    nodes = set()
    for test_file in rostest_files():
        for test in ElementTree.parse(test_file).getroot().iter("test"):
            for folder in [*ROOT.glob("src/*/test"), ROOT / "tests"]:
                nodes.update(path.resolve() for path in folder.glob(f"**/{test.get('type')}"))
    return nodes


def pytest_configure(config):
    config.addinivalue_line("markers", "long: a module whose tests take tens of seconds; the parallel run starts it "
                                       "first, so that it does not end waiting on one worker")
    config.rostest_nodes = _rostest_nodes()


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist reads the groups
def pytest_collection_modifyitems(items):
    """Long modules first; with ``--dist loadgroup`` every test goes to whichever worker is free, except that a
    module's tests that share a module- or class-scoped fixture (one simulator, one build) stay together."""
    items.sort(key=lambda item: item.get_closest_marker("long") is None)
    for item in items:
        fixtures = getattr(item, "_fixtureinfo", None)
        definitions = fixtures.name2fixturedefs.values() if fixtures else ()
        if any(definition.scope in ("module", "class") for chain in definitions for definition in chain):
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))


def pytest_ignore_collect(collection_path, config):
    return collection_path.resolve() in config.rostest_nodes or None


def pytest_collect_file(file_path, parent):
    if file_path.suffix == ".test" and file_path.resolve() in {path.resolve() for path in rostest_files()}:
        return RostestFile.from_parent(parent, path=file_path)
    return None


class RostestFile(pytest.File):
    def collect(self):
        yield RostestItem.from_parent(self, name=self.path.stem)


class RostestFailure(Exception):
    pass


class RostestItem(pytest.Item):
    """One rostest file: passes when rostest ran every test case of it and none failed."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.add_marker("long")

    def runtest(self):
        # Output goes to a file, not a pipe: a node that outlived rostest would hold a pipe open, and reading it
        # would wait for ever.
        with tempfile.TemporaryFile("w+") as log:
            try:
                returncode = subprocess.run(["rostest", "--text", str(self.path)], cwd=ROOT, stdout=log,
                                            stderr=subprocess.STDOUT, timeout=ROSTEST_TIMEOUT_SECONDS).returncode
            except subprocess.TimeoutExpired:
                returncode = None
            log.seek(0)
            output = log.read()
        tests = re.findall(r"\* TESTS: (\d+)", output)
        errors = re.findall(r"\* ERRORS: (\d+)", output)
        failures = re.findall(r"\* FAILURES: (\d+)", output)
        total = int(tests[-1]) if tests else 0
        failed = int(errors[-1]) + int(failures[-1]) if tests else 1
        if returncode != 0 and failed == 0:
            failed = 1
        self.user_properties += [("rostest_tests", total), ("rostest_failed", failed)]
        # The test nodes print their measurements as "figure: ..." lines; they join the other tests' figures.
        self.user_properties += [("figure", figure) for figure in re.findall(r"figure: (.*)", output)]
        if returncode is None:
            raise RostestFailure(f"{output}\nrostest {self.path} did not finish within {ROSTEST_TIMEOUT_SECONDS} s")
        if failed:
            raise RostestFailure(output)

    def repr_failure(self, excinfo):
        if isinstance(excinfo.value, RostestFailure):
            return str(excinfo.value)
        return super().repr_failure(excinfo)

    def reportinfo(self):
        return self.path, None, f"rostest {self.path.relative_to(ROOT)}"
