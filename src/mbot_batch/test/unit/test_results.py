"""A run's verdict, its files, the summary and the report page, without ROS."""
import csv
import json
from xml.etree import ElementTree

from mbot_batch import report, results
from mbot_batch.spec import Check, Run

CHECKS = {"distance": Check(minimum=1.0)}


def a_run(run_id="drive-1", seed=0, speed=0.1):
    return Run(run_id=run_id, scenario="drive", values={"seed": seed, "speed": speed},
               labels={"seed": str(seed), "speed": str(speed)}, repetition=0, seed=seed, launch_path="/l.launch",
               python_path="/s.py", rostest_path=None, launch_args={}, ros_params={},
               scenario_params={"speed": speed}, timeout=10.0)


def raw(**fields):
    return {"timeout": 10.0, "timed_out": False, "error": None, "exit_code": 0, "metrics": {}, **fields}


def test_metrics_are_read_exactly_from_the_scenario_output():
    value = 0.1 + 0.2
    text = f"noise\nmetric distance {value!r}\nmetric x 1\nmetric distance {value * 2!r}\nmetric bad word\n"
    metrics = results.parse_metrics(text)
    assert metrics == {"distance": value * 2, "x": 1.0, "bad": None}
    assert metrics["distance"].hex() == (value * 2).hex()


def test_a_rostest_scenarios_first_metric_is_read_after_unittests_test_name():
    text = ("test_the_mbot_moves_forward (__main__.Drive.test_the_mbot_moves_forward) ... metric x 0.25\n"
            "metric y -2e-07\nok\nnot a metric x 1\n")
    assert results.parse_metrics(text) == {"x": 0.25, "y": -2e-07}


def test_verdicts():
    assert results.verdict(raw(metrics={"distance": 2.0}), CHECKS)["status"] == "passed"
    failed = results.verdict(raw(metrics={"distance": 0.5}), CHECKS)
    assert failed["status"] == "failed" and failed["reason"] == "distance = 0.5, wanted >= 1"
    assert results.verdict(raw(), CHECKS)["reason"] == "distance = missing, wanted >= 1"
    assert results.verdict(raw(exit_code=3), CHECKS)["status"] == "error"
    timed_out = results.verdict(raw(timed_out=True), CHECKS)
    assert timed_out["status"] == "timeout" and "10 s" in timed_out["reason"]
    assert results.verdict(raw(exit_code=1, rostest={"tests": 2, "failed": 1}), {})["status"] == "failed"
    assert results.verdict(raw(rostest={"tests": 2, "failed": 0}), {})["status"] == "passed"
    assert results.verdict(raw(metrics={"distance": None}), CHECKS)["status"] == "error"


def finished(run, status_raw, wall=1.0):
    record = {"run_id": run.run_id, "scenario": run.scenario, **results.verdict(status_raw, CHECKS),
              "metrics": status_raw["metrics"], "attempts": 1, "wall_seconds": wall, "sim_seconds": 1.0,
              "worker": "tcp://w:1", "log_tail": "last line <b>"}
    return record


def test_files_of_a_run_the_summary_and_the_report(tmp_path):
    runs = [a_run("drive-1", 0, 0.1), a_run("drive-2", 1, 0.2), a_run("drive-3", 1, 0.3)]
    records = {"drive-1": finished(runs[0], raw(metrics={"distance": 2.0})),
               "drive-2": finished(runs[1], raw(metrics={"distance": 0.25}), wall=5.0)}
    for run in runs[:2]:
        results.write_result(str(tmp_path), run, records[run.run_id])
    assert results.load_result(str(tmp_path), "drive-2") == records["drive-2"]
    assert results.load_result(str(tmp_path), "drive-3") is None
    assert results.load_run(str(tmp_path), "drive-2") == runs[1]
    suite = ElementTree.parse(tmp_path / "runs" / "drive-2" / "junit.xml").getroot()
    assert suite.get("tests") == "2" and suite.get("failures") == "1"
    assert suite.find("testcase/failure").text == "last line <b>"
    assert json.loads((tmp_path / "runs" / "drive-1" / "metrics.json").read_text()) == {"distance": 2.0}

    results.write_summary(str(tmp_path / "summary.csv"), runs, records)
    rows = list(csv.DictReader((tmp_path / "summary.csv").open()))
    assert [row["status"] for row in rows] == ["passed", "failed", ""]
    assert rows[1]["distance"] == "0.25" and rows[1]["speed"] == "0.2"

    page = report.page("drive", runs, records, wall_seconds=12.0)
    assert page.count("<img") == 2 and "data:image/png;base64," in page
    assert "drive-2" in page and "distance = 0.25, wanted &gt;= 1" in page and "last line &lt;b&gt;" in page
    assert "2 of 3 runs finished: 1 failed, 1 passed" in page


def strict_json(path):
    """The file's JSON, refusing NaN and infinities as strict JSON does."""
    def refuse(constant):
        raise ValueError(f"{path}: {constant} is not strict JSON")
    with open(path) as stream:
        return json.load(stream, parse_constant=refuse)


def test_a_metric_that_is_not_finite_fails_its_run_is_recorded_in_strict_json_and_listed_by_the_report(tmp_path):
    from mbot_batch import engine
    from mbot_batch.spec import Scenario, Spec
    runs = [a_run("drive-1", 0, 0.1), a_run("drive-2", 1, 0.2), a_run("drive-3", 2, 0.3)]
    spec = Spec(path="/s.yaml", name="drive", scenarios={"drive": Scenario("drive", {}, checks=CHECKS)}, matrix={},
                repetitions=1, timeout=10.0, retries=0)
    raws = [raw(metrics={"distance": 2.0, "y": float("inf")}), raw(metrics={"distance": float("nan"), "y": 1.0}),
            raw(metrics={"distance": 1e308, "y": -1e999, "sim_time": float("inf")})]
    records = {run.run_id: engine.result_record(run, each, spec, 1, {}) for run, each in zip(runs, raws)}
    for run in runs:
        results.write_result(str(tmp_path), run, records[run.run_id])
    assert [(record["status"], record["reason"]) for record in records.values()] == [
        ("failed", "y = inf, not a finite number"), ("failed", "distance = nan, wanted >= 1"),
        ("failed", "y = -inf, not a finite number; sim_time = inf, not a finite number")]
    stored = strict_json(tmp_path / "runs" / "drive-3" / "result.json")
    assert stored["metrics"] == {"distance": 1e308, "y": "-inf", "sim_time": "inf"}
    assert strict_json(tmp_path / "runs" / "drive-2" / "metrics.json") == {"distance": "nan", "y": 1.0}
    assert stored == results.load_result(str(tmp_path), "drive-3")
    # As the batch wrote them before: NaN and Infinity in result.json, read back as floats.
    loaded = {run.run_id: results.load_result(str(tmp_path), run.run_id) for run in runs}
    loaded["drive-1"]["metrics"]["y"] = float("inf")
    for records_seen in (loaded, records):
        page = report.page("drive", runs, records_seen)
        assert page.count("<img") == 2
        listed = page.split("Metrics not drawn (5)", 1)[1]
        for run_id, name, value in (("drive-1", "y", "inf"), ("drive-2", "distance", "nan"),
                                    ("drive-3", "distance", "1e+308"), ("drive-3", "y", "-inf"),
                                    ("drive-3", "sim_time", "inf")):
            assert f"<code>{run_id}</code></td><td>{name}</td><td>{value}</td>" in listed
    results.write_summary(str(tmp_path / "summary.csv"), runs, records)
    rows = list(csv.DictReader((tmp_path / "summary.csv").open()))
    assert [row["y"] for row in rows] == ["inf", "1.0", "-inf"]


def test_the_metric_figure_draws_extreme_finite_values():
    """numpy's default bins fail on these (a span of 5e-324, one value of 1e300, a span past the largest float)."""
    for values in ([0.0, 5e-324], [1e300, 1e300], [-1e300, 1e300], [3.0], [1.0, 1.0 + 2.0 ** -52], [-7.0, 2.0]):
        runs = [a_run(f"drive-{index}", index, 0.1) for index in range(len(values))]
        records = {run.run_id: finished(run, raw(metrics={"distance": value})) for run, value in zip(runs, values)}
        assert report.page("drive", runs, records).count("<img") == 2, values
