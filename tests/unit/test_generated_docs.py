"""The READMEs' generated parts equal what their generators make from the code and the data: the speed table from
src/mbot_sim_bridge/bench/results.json, the lists of "What differs from Gazebo" from the code's own lists. The
short bench itself runs in integration/test_bench.py."""
import importlib.util
import os

WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


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

