#!/usr/bin/env python3
"""Run every test of the workspace: pytest (no master, or a private one), then each rostest file.

Prints one closing line, ``summary: N passed, N failed``, and exits non-zero on any failure. An optional
argument keeps only the test files whose path contains it.
"""
import glob
import os
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "build", "test_results")
# rostest files: each package's test/ folder and the workspace's tests/.
ROSTEST_GLOBS = ("src/*/test/*.test", "tests/*.test")
PYTEST_ROOTS = ("src/*/test", "tests")
# The longest rostest file takes under a minute; one that hangs is stopped and counted as failed.
ROSTEST_TIMEOUT_SECONDS = 600


def rostest_nodes(test_files):
    """Python files run by .test files as test nodes: pytest must not collect those."""
    nodes = set()
    for test_file in test_files:
        for test in ET.parse(test_file).getroot().iter("test"):
            nodes.update(glob.glob(os.path.join(ROOT, "src", "*", "test", "**", test.get("type")), recursive=True))
            nodes.update(glob.glob(os.path.join(ROOT, "tests", "**", test.get("type")), recursive=True))
    return nodes


def pytest_counts(report):
    suite = ET.parse(report).getroot()
    suite = suite if suite.tag == "testsuite" else suite.find("testsuite")
    total, failed = int(suite.get("tests")), int(suite.get("failures")) + int(suite.get("errors"))
    skipped = int(suite.get("skipped", 0))
    return total - failed - skipped, failed


def run_pytest(selected, ignored):
    report = os.path.join(RESULTS, "pytest.xml")
    roots = [path for pattern in PYTEST_ROOTS for path in sorted(glob.glob(os.path.join(ROOT, pattern)))]
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--junitxml", report,
               "--rootdir", ROOT] + ["--ignore=" + path for path in sorted(ignored)] + roots
    if selected:
        command += ["-k", selected]
    print("== pytest", flush=True)
    code = subprocess.call(command, cwd=ROOT)
    if code == 5:  # no tests selected by the filter
        return 0, 0
    if not os.path.exists(report):
        return 0, 1
    passed, failed = pytest_counts(report)
    return passed, failed + (1 if code not in (0, 1) else 0)


def run_rostest(test_file):
    print(f"== rostest {os.path.relpath(test_file, ROOT)}", flush=True)
    started = time.monotonic()
    # Output goes to a file, not a pipe: a node that outlived rostest would hold a pipe open, and reading it
    # would wait for ever.
    with tempfile.TemporaryFile("w+") as log:
        try:
            returncode = subprocess.run(["rostest", "--text", test_file], cwd=ROOT, stdout=log,
                                        stderr=subprocess.STDOUT, timeout=ROSTEST_TIMEOUT_SECONDS).returncode
        except subprocess.TimeoutExpired:
            returncode = None
        log.seek(0)
        output = log.read()
    if returncode is None:
        output += f"\nrostest {test_file} did not finish within {ROSTEST_TIMEOUT_SECONDS} s; stopped"
    tests = re.findall(r"\* TESTS: (\d+)", output)
    errors = re.findall(r"\* ERRORS: (\d+)", output)
    failures = re.findall(r"\* FAILURES: (\d+)", output)
    if returncode != 0 or not tests:
        print(output)
    else:
        # The test nodes print their measurements as "figure: ..." lines; show them, not the launch chatter.
        for figure in re.findall(r"figure: (.*)", output):
            print("   " + figure)
    total = int(tests[-1]) if tests else 0
    failed = (int(errors[-1]) + int(failures[-1])) if tests else 1
    if returncode != 0 and failed == 0:
        failed = 1
    print(f"   {total} tests, {failed} failed ({time.monotonic() - started:.0f} s)", flush=True)
    return total - min(failed, total), failed


def main():
    selected = sys.argv[1] if len(sys.argv) > 1 else ""
    os.makedirs(RESULTS, exist_ok=True)
    test_files = sorted(path for pattern in ROSTEST_GLOBS for path in glob.glob(os.path.join(ROOT, pattern)))
    passed, failed = run_pytest(selected, rostest_nodes(test_files))
    for test_file in test_files:
        if selected and selected not in os.path.relpath(test_file, ROOT):
            continue
        file_passed, file_failed = run_rostest(test_file)
        passed += file_passed
        failed += file_failed
    print(f"summary: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
