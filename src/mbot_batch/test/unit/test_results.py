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
