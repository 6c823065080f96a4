"""`./mbot bench --short`: every row of the bench runs and prints a finite figure, at smoke-test sizes that its
rows name, and a short run writes neither results.json nor the README's table (only a file --results names)."""
import importlib.util
import math
import os
import re
import subprocess

from mbot_sim_bridge.processes import stop_process_group

WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BENCH = os.path.join(WORKSPACE, "src", "mbot_sim_bridge", "bench")
_spec = importlib.util.spec_from_file_location("bench_results", os.path.join(BENCH, "results.py"))
results = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(results)

# What makes the full bench take minutes; a short run must not print them.
FULL_SIZES = ("50 lidar mbots", "5000 static boxes", "1280x720")
NUMBER = re.compile(r"-?\d+(?:\.\d+)?|\bnan\b|\binf\b", re.IGNORECASE)


def shape(figure: str) -> str:
    """A row's figure with its sizes left out: a short row and its full row have the same shape."""
    return re.sub(r"\d+", "N", figure)


def bench_files():
    """The bench folder's files, Python's bytecode cache aside."""
    return sorted(name for name in os.listdir(BENCH) if name != "__pycache__")


def test_the_short_bench_prints_every_row_with_a_finite_figure_and_writes_no_file():
    watched = (results.RESULTS, results.README)
    before = {path: open(path).read() for path in watched}
    files_before = bench_files()
    bench = subprocess.Popen([os.path.join(WORKSPACE, "mbot"), "bench", "--short"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        stdout, stderr = bench.communicate(timeout=600)
    finally:
        stop_process_group(bench)  # Ctrl-C's the bench, which stops its launches and masters
    assert bench.returncode == 0, stdout[-3000:] + stderr[-3000:]

    rows = [line[len(results.SHORT_MARK):].split(": ", 1) for line in stdout.splitlines()
            if line.startswith(results.SHORT_MARK)]
    # results.json holds every row of the full bench, in the order it prints them.
    assert [shape(figure) for figure, _ in rows] == [shape(row["figure"]) for row in results.load()["rows"]]
    for figure, value in rows:
        numbers = NUMBER.findall(value)
        assert numbers and all(math.isfinite(float(number)) for number in numbers), f"{figure}: {value}"
    assert not [figure for figure, _ in rows if any(size in figure for size in FULL_SIZES)]

    assert {path: open(path).read() for path in watched} == before, "--short wrote the results or the table"
    assert bench_files() == files_before
