#!/usr/bin/env python3
"""Run every test of the workspace through pytest: the Python tests and, as one item each, the rostest files
(see the workspace's conftest.py), spread over pytest-xdist workers.

Arguments go to pytest after the defaults, so ``-k PATTERN``, ``-n 1``, ``--durations=20`` or test paths narrow
or change the run; without test paths, pytest.ini's testpaths are run. Prints the measurements the tests recorded
(``figure`` properties), the run's wall time and one closing line, ``summary: N passed, N failed`` counting
rostest's test cases one by one; exits non-zero on any failure.
"""
import os
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPORT = os.path.join(ROOT, "build", "test_results", "pytest.xml")
# Most tests wait on ROS processes rather than compute, so twice as many workers as cores keep both busy;
# --dist loadgroup hands out tests one by one, keeping together those that share a module-scoped fixture (one
# simulator shared by a module's tests; see the workspace's conftest.py).
WORKERS = 2 * (os.cpu_count() or 1)
# The suite's time budget by area (tests/README.md, "The suite's budget"): an area's share of the wall time is the
# sum of its tests' durations over the number of workers. A test's area is the first of these whose prefix its
# junit classname (its path, dotted) has; rostest files, wherever they are, count as "rostest". The budgets are
# printed against what the run measured, never enforced: a timed test on a shared machine would flake.
AREAS = (
    ("simulator", ("src.mbot_sim_bridge.",), 40),
    ("batch", ("src.mbot_batch.",), 40),
    ("course", ("src.mbot_gazebo.", "src.mbot_teleop.", "src.mbot_description."), 12),
    ("integration", ("tests.integration.",), 130),
    ("docs and style", ("tests.unit.",), 6),
    ("stand-ins", ("src.",), 12),
)
ROSTEST_BUDGET_SECONDS = 75


def area_of(classname, is_rostest):
    if is_rostest:
        return "rostest"
    return next((name for name, prefixes, _ in AREAS if classname.startswith(prefixes)), "other")


def count(report):
    """(passed, failed, skipped, figures, seconds by area) from pytest's junit report; a rostest item counts its
    test cases."""
    passed = failed = skipped = 0
    figures = []
    area_seconds = {}
    for case in ET.parse(report).getroot().iter("testcase"):
        properties = {}
        for prop in case.iter("property"):
            if prop.get("name") == "figure":
                figures.append(prop.get("value"))
            else:
                properties[prop.get("name")] = prop.get("value")
        outcome_failed = case.find("failure") is not None or case.find("error") is not None
        area = area_of(case.get("classname", ""), "rostest_tests" in properties)
        area_seconds[area] = area_seconds.get(area, 0.0) + float(case.get("time") or 0.0)
        if "rostest_tests" in properties:
            cases, cases_failed = int(properties["rostest_tests"]), int(properties["rostest_failed"])
            passed += cases - min(cases_failed, cases)
            failed += max(cases_failed, 1 if outcome_failed else 0)
        elif outcome_failed:
            failed += 1
        elif case.find("skipped") is not None:
            skipped += 1
        else:
            passed += 1
    return passed, failed, skipped, figures, area_seconds


def budget_lines(area_seconds, workers):
    """One line an area: its share of the wall time against its budget, most expensive first."""
    budgets = {name: budget for name, _, budget in AREAS}
    budgets["rostest"] = ROSTEST_BUDGET_SECONDS
    lines = []
    for area, seconds in sorted(area_seconds.items(), key=lambda item: -item[1]):
        share = seconds / workers
        budget = budgets.get(area)
        verdict = "no budget" if budget is None else f"budget {budget} s" + (", OVER" if share > budget else "")
        lines.append(f"area {area}: {share:.0f} s of the wall time ({seconds:.0f} s over {workers} workers; "
                     f"{verdict})")
    return lines


def workers_of(arguments):
    """The number of workers the run had: the default, or the last -n given."""
    workers = WORKERS
    for flag, value in zip(arguments, arguments[1:]):
        if flag == "-n" and value.isdigit():
            workers = max(int(value), 1)
    return workers


def main(arguments):
    os.makedirs(os.path.dirname(REPORT), exist_ok=True)
    if os.path.exists(REPORT):
        os.remove(REPORT)
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir", ROOT,
               "--junitxml", REPORT, "-n", str(WORKERS), "--dist", "loadgroup", "--durations", "10",
               *arguments]  # without test paths, pytest.ini's testpaths
    started = time.monotonic()
    code = subprocess.call(command, cwd=ROOT)
    minutes, seconds = divmod(round(time.monotonic() - started), 60)
    # The suite's size and time are said here, where every run measures them, and nowhere else.
    print(f"wall time: {minutes}:{seconds:02d}")
    if code == 5:  # nothing selected by the filter
        print("summary: 0 passed, 0 failed")
        return 0
    if not os.path.exists(REPORT):
        print("summary: 0 passed, 1 failed")
        return 1
    passed, failed, skipped, figures, area_seconds = count(REPORT)
    if code not in (0, 1) and not failed:
        failed = 1
    for figure in figures:
        print(f"figure: {figure}")
    for line in budget_lines(area_seconds, workers_of(arguments)):
        print(line)
    print(f"summary: {passed} passed, {failed} failed" + (f", {skipped} skipped" if skipped else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
