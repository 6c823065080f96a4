"""A batch's output folder, free of ROS: per run ``runs/RUN_ID/`` with ``run.json`` (what ran), ``result.json``
(the verdict, written last: its presence marks the run finished), ``metrics.json``, ``junit.xml`` and
``logs/attempt-N/``; beside them ``summary.csv`` and ``report.html``.

A run's verdict comes from what its run process saw (``raw``: exit status, metrics printed, timeout, rostest's
counts) and the scenario's checks."""
import csv
import json
import math
import os
import re
import tempfile
from contextlib import contextmanager
from typing import Dict, List, Optional
from xml.etree import ElementTree

from .spec import Check, Run

# A rostest scenario's metrics may follow unittest's verbose "test_name (module.Case) ... " on its line, which it
# ends only with the test's outcome.
METRIC_LINE = re.compile(r"^(?:test\S* \(\S+\) \.\.\. )?metric (\S+) (\S+)\s*$", re.MULTILINE)
PASSED, FAILED, ERROR, TIMEOUT = "passed", "failed", "error", "timeout"
# A run that crashed, hung or whose worker died is retried as the spec says; a verdict from its checks is final.
RETRIED = (ERROR, TIMEOUT)
LOG_TAIL_LINES = 20


def parse_metrics(text: str) -> Dict[str, float]:
    """The ``metric NAME VALUE`` lines a scenario printed (``mbot_batch.scenario.metric``); the last one of a name
    counts. A value that is not a number is left out here and reported by ``verdict``."""
    metrics = {}
    for name, value in METRIC_LINE.findall(text):
        try:
            metrics[name] = float(value)
        except ValueError:
            metrics[name] = None
    return metrics


def recorded(value):
    """A metric as result.json and metrics.json hold it: strict JSON has no NaN or infinities, so those are the texts
    "nan", "inf" and "-inf" (``float()`` reads them back); a finite value as it is."""
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    return value


def finite(value) -> bool:
    """A metric a figure can draw: a finite number (not a recorded "nan", "inf" or "-inf", nor a missing one)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def log_tail(text: str, lines: int = LOG_TAIL_LINES) -> str:
    return "\n".join(text.rstrip("\n").splitlines()[-lines:])


def verdict(raw: dict, checks: Dict[str, Check]) -> dict:
    """{status, reason, completed, checks: [{metric, value, bounds, min, max, passed}]} of a run from its run
    process's ``raw`` record: ``timed_out``, ``error`` (the run could not be run), ``exit_code``, ``metrics``,
    ``rostest`` ({tests, failed}). ``completed``: the scenario ran to its end (and rostest's cases passed), so
    that only the checks can have failed."""
    metrics = raw.get("metrics") or {}
    results = [{"metric": name, "value": recorded(metrics.get(name)), "bounds": check.describe(), "min": check.minimum,
                "max": check.maximum, "passed": metrics.get(name) is not None and check.passes(metrics[name])}
               for name, check in checks.items()]

    def outcome(status, reason, completed=False):
        return {"status": status, "reason": reason, "completed": completed, "checks": results}
    rostest = raw.get("rostest")
    if raw.get("timed_out"):
        return outcome(TIMEOUT, f"killed at its timeout of {raw['timeout']:g} s")
    if raw.get("error"):
        return outcome(ERROR, raw["error"])
    if raw.get("exit_code") not in (0, None) and not rostest:
        return outcome(ERROR, f"the scenario exited with status {raw['exit_code']}")
    if rostest and (rostest["failed"] or not rostest["tests"]):
        return outcome(FAILED, f"rostest: {rostest['failed']} of {rostest['tests']} test cases failed")
    bad = [name for name, value in metrics.items() if value is None]
    if bad:
        return outcome(ERROR, f"metric '{bad[0]}' is not a number")
    failing = [f"{check['metric']} = {'missing' if check['value'] is None else _text(check['value'])}, "
               f"wanted {check['bounds']}" for check in results if not check["passed"]]
    # Deterministic like a check's verdict, so failed rather than an error to retry.
    failing += [f"{name} = {value!r}, not a finite number" for name, value in metrics.items()
                if name not in checks and not math.isfinite(value)]
    if failing:
        return outcome(FAILED, "; ".join(failing), completed=True)
    return outcome(PASSED, "", completed=True)


def _text(value) -> str:
    return format(value, "g") if isinstance(value, float) else str(value)


def run_folder(out: str, run_id: str) -> str:
    return os.path.join(out, "runs", run_id)


@contextmanager
def replacing(path: str, mode: str = "w", **options):
    """A stream into a temporary file beside ``path``, renamed onto it when the block ends well: a driver killed or
    interrupted mid-write leaves the earlier file whole (no half report, no half result for the resume to trust)."""
    folder = os.path.dirname(path) or "."
    os.makedirs(folder, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=folder, prefix=f".{os.path.basename(path)}.", suffix=".tmp")
    try:
        with os.fdopen(handle, mode, **options) as stream:
            yield stream
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise


def write_json(path: str, data):
    """Strict JSON (no NaN or infinities: ``recorded`` turns them into texts), written whole or not at all."""
    with replacing(path) as stream:
        json.dump(data, stream, indent=1, sort_keys=True, allow_nan=False)


def write_text(path: str, text: str):
    with replacing(path) as stream:
        stream.write(text)


def write_bytes(path: str, data: bytes):
    with replacing(path, "wb") as stream:
        stream.write(data)


def write_attempt_logs(out: str, run_id: str, attempt: int, logs: Dict[str, str]) -> str:
    folder = os.path.join(run_folder(out, run_id), "logs", f"attempt-{attempt}")
    for name, text in logs.items():
        write_text(os.path.join(folder, name), text)
    return folder


def write_result(out: str, run: Run, result: dict):
    """The finished run: metrics.json, junit.xml, then result.json last."""
    folder = run_folder(out, run.run_id)
    write_json(os.path.join(folder, "run.json"), run.to_dict())
    write_json(os.path.join(folder, "metrics.json"), result["metrics"])
    with replacing(os.path.join(folder, "junit.xml")) as stream:
        ElementTree.ElementTree(junit(run, result)).write(stream, encoding="unicode", xml_declaration=True)
    write_json(os.path.join(folder, "result.json"), result)


def junit(run: Run, result: dict) -> ElementTree.Element:
    """One test suite per run: a case for the run itself (its verdict, the log tail on failure) and one per check."""
    suite = ElementTree.Element("testsuite", name=run.run_id, time=f"{result['wall_seconds']:.3f}")
    properties = ElementTree.SubElement(suite, "properties")
    for key, value in [("scenario", run.scenario), ("seed", run.seed), ("repetition", run.repetition),
                       *((f"matrix.{key}", json.dumps(value)) for key, value in run.values.items())]:
        ElementTree.SubElement(properties, "property", name=key, value=str(value))
    cases = [("run", result["completed"], result["reason"])]
    cases += [(f"metric {check['metric']} {check['bounds']}", check["passed"],
               f"{check['metric']} = {check['value']}") for check in result["checks"]]
    failures = 0
    for name, passed, message in cases:
        case = ElementTree.SubElement(suite, "testcase", classname=run.scenario, name=name)
        if not passed:
            failures += 1
            element = "error" if result["status"] in RETRIED else "failure"
            ElementTree.SubElement(case, element, message=message or result["status"]).text = result["log_tail"]
    suite.set("tests", str(len(cases)))
    suite.set("failures", str(failures))
    return suite


def load_result(out: str, run_id: str) -> Optional[dict]:
    try:
        with open(os.path.join(run_folder(out, run_id), "result.json")) as stream:
            return json.load(stream)
    except (OSError, ValueError):
        return None


def load_run(out: str, run_id: str) -> Run:
    with open(os.path.join(run_folder(out, run_id), "run.json")) as stream:
        return Run.from_dict(json.load(stream))


SUMMARY_COLUMNS = ("run_id", "scenario", "status", "reason", "attempts", "wall_seconds", "sim_seconds", "worker")


def write_summary(path: str, runs: List[Run], results: Dict[str, dict]):
    """One row per run of the spec (those not run yet have no status), the matrix values and the metrics as
    columns of their own."""
    matrix_keys = sorted({key for run in runs for key in run.values})
    metric_names = sorted({name for result in results.values() for name in result["metrics"]})
    with replacing(path, newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow([*SUMMARY_COLUMNS, *matrix_keys, *metric_names])
        for run in runs:
            result = results.get(run.run_id, {})
            writer.writerow([run.run_id, run.scenario, *(result.get(column, "") for column in SUMMARY_COLUMNS[2:]),
                             *(_cell(run.values.get(key, "")) for key in matrix_keys),
                             *(_cell(result.get("metrics", {}).get(name, "")) for name in metric_names)])


def _cell(value) -> str:
    if isinstance(value, dict):
        return json.dumps(value, sort_keys=True)
    return repr(value) if isinstance(value, float) else str(value)
