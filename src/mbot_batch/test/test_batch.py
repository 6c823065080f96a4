"""./mbot batch end to end, on 12 short runs (two seeds and two speeds: the mbot drives for a second of sim time
in the empty world as a Python scenario and as a rostest file, and a box slides in the simulator alone):

- the embedded default: the driver killed (SIGKILL) after two runs, then Ctrl-C'd, then run to the end, each
  time resuming and skipping finished runs; no process of a run is left after a kill or a Ctrl-C;
- a real two-node cluster (``dask scheduler`` and two ``dask worker`` processes, each in its own process group),
  one worker killed while it runs a run: the run is rescheduled and each of the 12 results equals the embedded
  one;
- a second batch into the folder of one that runs is refused, and changes nothing;
- a hanging run killed at its timeout with its hostile children (one ignoring SIGTERM, one started with a clean
  environment, a double-forked orphan), retried, reported with its log tail;
- the rostest scenario's runs of that batch: their test cases' verdict and their metrics;
- a failing run rerun with ``mbot batch rerun``: its metrics, read from its log, come out bit-identical, and a
  batch metric changed by one ulp is reported as DIFFERS with exit status 1;
- the report page's figures in a headless Chromium screenshot.
"""
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import uuid

import pytest
from mbot_batch.engine import folder_token
from mbot_batch.results import load_result
from mbot_batch.run import processes_with_token
from ros_processes import folder_bytes, processes_named, wait_until

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenarios"))
from hang import HOSTILE_CHILDREN  # noqa: E402 - the scenarios' folder is no package

pytestmark = pytest.mark.long

HERE = os.path.dirname(os.path.abspath(__file__))
BATCH = os.path.join(HERE, os.pardir, "scripts", "mbot_batch")
SPEC = os.path.join(HERE, "scenarios", "drive.yaml")
RUNS = 12
BATCH_TIMEOUT = 240
CTRL_C_SECONDS = 5.0


def start_batch(out, *options, spec=SPEC):
    log = open(os.path.join(os.path.dirname(out), f"driver-{time.monotonic_ns()}.log"), "w")
    with log:
        # SIGINT as in a terminal's foreground: a runner started as a background job passes it on ignored.
        return subprocess.Popen([sys.executable, BATCH, spec, "-o", out, "--quiet", *options], stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def finished(out):
    folder = os.path.join(out, "runs")
    return {run_id for run_id in (os.listdir(folder) if os.path.isdir(folder) else ())
            if os.path.exists(os.path.join(folder, run_id, "result.json"))}


def result_files(out):
    return {run_id: os.stat(os.path.join(out, "runs", run_id, "result.json")).st_mtime_ns for run_id in finished(out)}


# Waits that scan every process's environment poll at this interval, not wait_until's 20 ms: a scan reads a few
# hundred /proc files, and at 50 scans a second the waits cost the test seconds of CPU.
SCAN_INTERVAL = 0.2


def assert_no_run_processes(out, timeout=3.0):
    wait_until(lambda: not processes_with_token(folder_token(out)), timeout, f"the runs of {out} to be gone",
               interval=SCAN_INTERVAL)


def scheduling_policies(pids):
    policies = set()
    for pid in pids:
        try:
            policies.add(os.sched_getscheduler(pid))
        except OSError:
            continue  # ended meanwhile
    return policies


def stop_group(process):
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    process.wait()


@pytest.fixture(scope="module")
def embedded(tmp_path_factory):
    """The 12 runs on the embedded default, interrupted twice on the way (one worker until then: each worker
    process costs its start-up again); what each interruption left."""
    out = str(tmp_path_factory.mktemp("embedded") / "out")
    seen = {}
    driver = start_batch(out, "--workers", "1")
    try:
        wait_until(lambda: len(finished(out)) >= 2, BATCH_TIMEOUT, "two finished runs")
        driver.send_signal(signal.SIGKILL)  # the driver alone, as the kernel's OOM killer would
        driver.wait()
        assert_no_run_processes(out, timeout=10.0)  # each run process sees its worker die and kills its run
        seen["after kill"] = result_files(out)

        driver = start_batch(out, "--workers", "1")
        # The run process and a process it started (after it set its policy, which they inherit).
        wait_until(lambda: len(processes_with_token(folder_token(out))) >= 2, 60, "a resumed run to be running",
                   interval=SCAN_INTERVAL)
        seen["policies"] = scheduling_policies(processes_with_token(folder_token(out)))
        # A second batch into the same folder meanwhile: refused before it writes anything.
        before = {name: data for name, data in folder_bytes(out).items() if not name.startswith("runs")}
        second = subprocess.run([sys.executable, BATCH, SPEC, "-o", out, "--quiet"], capture_output=True, text=True,
                                timeout=60)
        seen["second batch"] = (second.returncode, second.stderr, before,
                                {name: data for name, data in folder_bytes(out).items() if not name.startswith("runs")})
        interrupted = time.monotonic()
        os.killpg(driver.pid, signal.SIGINT)  # as Ctrl-C in a terminal: the driver and its workers
        seen["ctrl-c exit"] = driver.wait(timeout=30)
        seen["ctrl-c seconds"] = time.monotonic() - interrupted
        seen["left after ctrl-c"] = processes_with_token(folder_token(out))
        seen["after ctrl-c"] = result_files(out)

        driver = start_batch(out)  # the embedded default: a worker per core
        driver.wait(timeout=BATCH_TIMEOUT)
        seen["exit"] = driver.returncode
    finally:
        stop_group(driver)
    return out, seen


def test_a_killed_or_interrupted_driver_resumes_and_skips_finished_runs(embedded):
    out, seen = embedded
    assert seen["exit"] == 1  # the runs at speed 0 fail their check
    assert len(finished(out)) == RUNS
    final = result_files(out)
    for stage in ("after kill", "after ctrl-c"):
        assert {run_id: final[run_id] for run_id in seen[stage]} == seen[stage], f"a run finished {stage} ran again"
    assert seen["policies"] == {os.SCHED_BATCH}, "a run's processes are batch tasks"
    status, message, before, after = seen["second batch"]
    assert status == 2 and message.count("\n") == 1, message
    assert re.fullmatch(rf"mbot batch: {re.escape(out)} is in use by another batch \(pid \d+ on .+ since .+\): "
                        r"wait for it to end, or give another -o\n", message), message
    assert after == before, "the refused batch changed the folder"
    assert seen["ctrl-c exit"] == 130
    print(f"figure: batch: Ctrl-C to the driver's exit {seen['ctrl-c seconds']:.1f} s, no run process left")
    assert seen["ctrl-c seconds"] < CTRL_C_SECONDS
    assert seen["left after ctrl-c"] == []
    with open(os.path.join(out, "summary.csv")) as summary:
        assert len(summary.read().splitlines()) == RUNS + 1
    for run_id in finished(out):
        assert {"junit.xml", "metrics.json", "run.json", "logs"} <= set(os.listdir(os.path.join(out, "runs", run_id)))
    assert_no_run_processes(out)


@pytest.fixture
def cluster(tmp_path):
    """A scheduler and two single-threaded workers, each in a process group of its own, as Dask's docs start a
    cluster by hand (``dask scheduler``, ``dask worker ADDRESS``)."""
    scheduler_file = str(tmp_path / "scheduler.json")
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    logs = [open(tmp_path / f"{name}.log", "w") for name in ("scheduler", "worker-1", "worker-2")]
    processes = [subprocess.Popen([*dask, "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                   "--scheduler-file", scheduler_file], stdout=logs[0], stderr=subprocess.STDOUT,
                                  start_new_session=True)]
    try:
        wait_until(lambda: _address(scheduler_file), 60, "the scheduler's address")
        for index, log in enumerate(logs[1:], 1):
            processes.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", scheduler_file,
                 "--nthreads", "1", "--name", f"worker-{index}", "--no-dashboard"],
                stdout=log, stderr=subprocess.STDOUT, start_new_session=True))
        yield _address(scheduler_file), processes[1], processes[2]
    finally:
        for process in processes:
            stop_group(process)
        for log in logs:
            log.close()


def _address(scheduler_file):
    try:
        with open(scheduler_file) as stream:
            return json.load(stream)["address"]
    except (OSError, ValueError, KeyError):
        return None  # not written yet, or half written


def test_a_two_node_cluster_gives_the_embedded_results_and_reschedules_a_killed_workers_run(embedded, cluster,
                                                                                           tmp_path):
    reference, _ = embedded
    address, doomed, survivor = cluster
    out = str(tmp_path / "out")
    driver = start_batch(out, "--address", address)
    try:
        def doomed_run():
            for pid in processes_with_token(folder_token(out)):
                try:
                    if os.getpgid(_parent(pid)) == doomed.pid:
                        return _token(pid).split(":")[1]
                except (OSError, ValueError):
                    continue
            return None
        wait_until(doomed_run, BATCH_TIMEOUT, "a run on the first worker", interval=SCAN_INTERVAL)
        killed_run = doomed_run()
        os.killpg(doomed.pid, signal.SIGKILL)  # the whole node: its nanny and worker process
        driver.wait(timeout=BATCH_TIMEOUT)
    finally:
        stop_group(driver)
    assert driver.returncode == 1
    assert len(finished(out)) == RUNS and finished(out) == finished(reference)
    rescheduled = load_result(out, killed_run)
    print(f"figure: batch: {killed_run}, its worker killed, finished on {rescheduled['worker']}")
    assert rescheduled["attempts"] == 1 and rescheduled["status"] == load_result(reference, killed_run)["status"]
    for run_id in finished(out):
        mine, theirs = load_result(out, run_id), load_result(reference, run_id)
        assert (mine["status"], mine["metrics"]) == (theirs["status"], theirs["metrics"]), run_id
    assert_no_run_processes(out, timeout=10.0)


def _parent(pid):
    with open(f"/proc/{pid}/stat") as stream:
        return int(stream.read().rsplit(")", 1)[1].split()[1])


def _token(pid):
    with open(f"/proc/{pid}/environ", "rb") as stream:
        return next(v for v in stream.read().split(b"\0") if v.startswith(b"MBOT_BATCH_RUN=")).decode().split("=")[1]


def test_a_hanging_run_is_killed_at_its_timeout_retried_and_reported_with_its_log_tail(tmp_path):
    spec = tmp_path / "hang.yaml"
    marker = f"mbot-batch-test-child-{uuid.uuid4().hex[:8]}"
    # The simulator alone (no robot to describe and spawn): what hangs is the scenario.
    spec.write_text("scenarios:\n  hang:\n    launch: gazebo_ros empty_world.launch\n    python: hang.py\n"
                    f"matrix:\n  seed: [0]\n  marker: [{marker}]\ntimeout: 8\nretries: 1\n")
    shutil.copy(os.path.join(HERE, "scenarios", "hang.py"), tmp_path)
    out = str(tmp_path / "out")
    driver = start_batch(out, "--workers", "1", spec=str(spec))
    try:
        wait_until(lambda: len(processes_named(marker)) == HOSTILE_CHILDREN, 60, "the hanging run's children",
                   interval=SCAN_INTERVAL)
        assert driver.wait(timeout=BATCH_TIMEOUT) == 1
        # None outlived its run, the clean environment's and the orphan's included.
        assert processes_named(marker) == []
    finally:
        stop_group(driver)
        for pid in processes_named(marker):
            os.kill(pid, signal.SIGKILL)
    (run_id,) = finished(out)
    result = load_result(out, run_id)
    assert result["status"] == "timeout" and result["attempts"] == 2, result
    assert 8.0 <= result["wall_seconds"] < 8.0 + 5.0
    assert "hanging on purpose" in result["log_tail"]
    assert sorted(os.listdir(os.path.join(out, "runs", run_id, "logs"))) == ["attempt-1", "attempt-2"]
    with open(os.path.join(out, "runs", run_id, "junit.xml")) as junit:
        assert "hanging on purpose" in junit.read()
    with open(os.path.join(out, "report.html")) as report:
        assert run_id in report.read()
    assert_no_run_processes(out)


def test_a_rostest_scenario_counts_its_test_cases_and_metrics(embedded):
    out, _ = embedded
    results = [load_result(out, run_id) for run_id in finished(out)]
    verdicts = sorted((result["metrics"]["x"] > 0.05, result["status"], result["reason"])
                      for result in results if result["scenario"] == "drive_test")
    assert verdicts == [(False, "failed", "rostest: 1 of 1 test cases failed")] * 2 + [(True, "passed", "")] * 2


def test_rerunning_a_failing_run_reproduces_its_metrics_bit_identically_and_reports_a_differing_one(embedded,
                                                                                                    tmp_path):
    """One rerun, of a copy of the batch's folder in which one recorded metric is one ulp off: the rerun's own
    metrics (its log's lines, read here) equal the batch's bit for bit, and the changed one must be reported."""
    reference, _ = embedded
    failing = sorted(run_id for run_id in finished(reference) if load_result(reference, run_id)["status"] == "failed"
                     and load_result(reference, run_id)["scenario"] == "drive")
    assert failing
    run_id = failing[0]
    out = str(tmp_path / "out")
    shutil.copytree(os.path.join(reference, "runs", run_id), os.path.join(out, "runs", run_id))
    result_file = os.path.join(out, "runs", run_id, "result.json")
    with open(result_file) as stream:
        recorded = json.load(stream)
    changed = sorted(recorded["metrics"])[0]
    recorded["metrics"][changed] = math.nextafter(recorded["metrics"][changed], math.inf)
    with open(result_file, "w") as stream:
        json.dump(recorded, stream)
    rerun = subprocess.run([sys.executable, BATCH, "rerun", out, run_id], capture_output=True, text=True,
                           timeout=120)
    assert rerun.returncode == 1, rerun.stdout + rerun.stderr
    assert "status: failed" in rerun.stdout and "metrics differ from the batch's" in rerun.stdout
    verdicts = dict(re.findall(r"^  (\S+): .* (bit-identical|DIFFERS)$", rerun.stdout, re.MULTILINE))
    assert verdicts == {name: "DIFFERS" if name == changed else "bit-identical" for name in recorded["metrics"]}
    with open(os.path.join(out, "reruns", run_id, "scenario.log")) as stream:
        rerun_metrics = dict(re.findall(r"^metric (\S+) (\S+)$", stream.read(), re.MULTILINE))
    batch_metrics = load_result(reference, run_id)["metrics"]
    assert {name: float(value).hex() for name, value in rerun_metrics.items()} == \
        {name: float(value).hex() for name, value in batch_metrics.items()}


def test_the_report_shows_its_figures_in_a_browser(embedded, tmp_path):
    out, _ = embedded
    screenshot = tmp_path / "report.png"
    subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", f"--user-data-dir={tmp_path}/chrome",
                    f"--screenshot={screenshot}", "--window-size=1200,2400", f"file://{out}/report.html"],
                   capture_output=True, timeout=120, check=True)
    import numpy
    from PIL import Image
    pixels = numpy.asarray(Image.open(screenshot).convert("RGB")).reshape(-1, 3)
    # The bars of the pass-rate figure (green: all passed, orange: some failed) and the metric histograms (blue).
    for name, colour in (("passed bars", (0x44, 0xaa, 0x44)), ("failing bars", (0xcc, 0x88, 0x44)),
                         ("histogram bars", (0x44, 0x88, 0xcc))):
        assert (numpy.abs(pixels.astype(int) - colour).sum(axis=1) < 30).sum() > 500, f"no {name} in the screenshot"
