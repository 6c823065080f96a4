"""The READMEs' generated parts equal what their generators make from the code and the data: the speed table from
src/mbot_sim_bridge/bench/results.json, the lists of "What differs from Gazebo" from the code's own lists. The
short bench itself (every figure printed and recorded) runs with MBOT_FULL_SWEEP=1: it launches every bench setup,
50 robots included, which takes minutes."""
import importlib.util
import json
import os
import subprocess
import sys

import pytest

WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BENCH = os.path.join(WORKSPACE, "src", "mbot_sim_bridge", "bench")


def load_module(path):
    spec = importlib.util.spec_from_file_location(os.path.splitext(os.path.basename(path))[0], path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


generate_docs = load_module(os.path.join(WORKSPACE, "docs", "generate_docs.py"))
results = generate_docs.results


def test_the_speed_table_is_the_one_generated_from_the_results_file():
    text = open(results.README).read()
    assert text.count(results.TABLE_START) == 1, "the bridge README has no speed table, or two"
    assert results.with_table(text, results.load()) == text, "run: python3 docs/generate_docs.py"


def test_the_results_file_has_its_date_machine_raw_figure_and_rows():
    data = results.load()
    assert {"date", "machine", "raw_pybullet_real_time_factor", "note", "rows"} <= set(data)
    assert data["raw_pybullet_real_time_factor"] > 0 and data["rows"]
    assert all(set(row) == {"figure", "value"} for row in data["rows"])


def test_what_differs_lists_are_the_ones_generated_from_the_code():
    text = open(generate_docs.README).read()
    assert generate_docs.with_block(text) == text, "run: python3 docs/generate_docs.py"


@pytest.mark.skipif(not os.environ.get("MBOT_FULL_SWEEP"), reason="minutes: every bench setup (MBOT_FULL_SWEEP=1)")
def test_the_short_bench_prints_and_records_every_figure_of_the_results_file(tmp_path):
    written = tmp_path / "results.json"
    run = subprocess.run([sys.executable, os.path.join(BENCH, "bench_bridge.py"), "--short", "--results",
                          str(written)], capture_output=True, text=True, timeout=1200)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    figures = [row["figure"] for row in json.loads(written.read_text())["rows"]]
    assert figures == [row["figure"] for row in results.load()["rows"]]
    assert all(f"{figure}: " in run.stdout for figure in figures)
