"""The driver without Dask, on a folder whose runs are all finished (so it goes straight to the summary and the
report): Ctrl-C at each of its phases, a second batch into a folder in use, and concurrent batches into one folder."""
import os
import random
import re
import subprocess
import sys

import pytest
from mbot_batch import cli, engine, launch_files, report, results, spec
from ros_processes import folder_bytes

FULL_SWEEP = bool(os.environ.get("MBOT_FULL_SWEEP"))
SPEC = """\
scenarios:
  drive:
    launch: pkg good.launch
    python: scenario.py
    metrics: {distance: {min: 1.0}}
matrix:
  seed: [0, 1]
  speed: [0.1, 0.2]
"""


def resolver(reference, folder, where):
    return "/ws/pkg/good.launch", ("gui", "lockstep", "seed")


@pytest.fixture
def finished_batch(tmp_path, monkeypatch):
    """(spec path, output folder, its files' bytes): every run finished, the summary and report written once."""
    monkeypatch.setattr(launch_files, "resolve", resolver)
    (tmp_path / "scenario.py").write_text("")
    path = tmp_path / "drive.yaml"
    path.write_text(SPEC)
    out = str(tmp_path / "out")
    for index, run in enumerate(spec.load(str(path), resolver).runs()):
        metrics = {"distance": 0.5 + index, "sim_time": 1.0}
        raw = {"timeout": 10.0, "timed_out": False, "error": None, "exit_code": 0, "metrics": metrics}
        results.write_result(out, run, {"run_id": run.run_id, "scenario": run.scenario,
                                        **results.verdict(raw, {"distance": spec.Check(1.0)}), "metrics": metrics,
                                        "attempts": 1, "wall_seconds": 1.0, "sim_seconds": 1.0, "worker": "w",
                                        "log_tail": ""})
    assert cli.main([str(path), "-o", out, "--quiet"]) == 1
    return str(path), out, folder_bytes(out)


def interrupt(*_, **__):
    raise KeyboardInterrupt


# Where a Ctrl-C can land: the spec's check, the folder's lock, the spec's copy, the results read for the resume,
# a row of the summary, a figure of the report, and any file's rename into place.
PHASES = [(spec, "load"), (engine, "folder_lock"), (engine, "write_bytes"), (engine, "load_result"),
          (results, "_cell"), (report, "_metric_distributions"), (results.os, "replace")]


@pytest.mark.parametrize("module, name", PHASES, ids=[name for _, name in PHASES])
def test_ctrl_c_at_any_phase_exits_130_and_leaves_every_file_whole(finished_batch, monkeypatch, capsys, module,
                                                                   name):
    path, out, before = finished_batch
    monkeypatch.setattr(module, name, interrupt)
    try:
        status = cli.main([path, "-o", out, "--quiet"])
    except KeyboardInterrupt:
        pytest.fail(f"Ctrl-C in {name} ended the batch with a raw KeyboardInterrupt")
    assert status == 130
    assert "Traceback" not in capsys.readouterr().err
    after = folder_bytes(out)
    assert after.pop(engine.LOCK_FILE, b"").startswith(b"pid ")  # who held it last
    assert after == {name: data for name, data in before.items() if name != engine.LOCK_FILE}  # nothing cut short


def test_a_second_batch_into_a_folder_in_use_is_refused_and_a_killed_holder_leaves_no_lock(finished_batch,
                                                                                           capsys):
    path, out, before = finished_batch
    holder = subprocess.Popen([sys.executable, "-c", "import sys; from mbot_batch.engine import folder_lock\n"
                               f"with folder_lock({out!r}):\n    print('held', flush=True); sys.stdin.read()"],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "held\n"
        assert cli.main([path, "-o", out, "--quiet"]) == 2
        message = capsys.readouterr().err
        assert re.fullmatch(rf"mbot batch: {re.escape(out)} is in use by another batch \(pid {holder.pid} on "
                            r".+ since .+\): wait for it to end, or give another -o\n", message), message
        after = folder_bytes(out)
        assert after.pop(engine.LOCK_FILE).startswith(f"pid {holder.pid} ".encode())
        assert after == {name: data for name, data in before.items() if name != engine.LOCK_FILE}
    finally:
        holder.kill()  # as a driver killed: the kernel drops its lock
        holder.wait()
    assert cli.main([path, "-o", out, "--quiet"]) == 1


def test_concurrent_batches_into_one_folder_are_refused_or_finish_with_every_result_whole(finished_batch):
    """Seeded: drivers started together (with random delays) into one folder; each is refused with its one line or
    finishes, and every result and report stays whole. MBOT_FULL_SWEEP=1: more rounds of more drivers."""
    path, out, before = finished_batch
    chooser = random.Random(54)
    for _ in range(5 if FULL_SWEEP else 1):
        delays = [chooser.uniform(0, 0.3) for _ in range(chooser.randint(2, 6) if FULL_SWEEP else 2)]
        code = ("import sys, time; time.sleep(float(sys.argv[1])); from mbot_batch import cli, launch_files\n"
                f"launch_files.resolve = lambda *_: ('/ws/pkg/good.launch', ('gui', 'lockstep', 'seed'))\n"
                f"sys.exit(cli.main([{path!r}, '-o', {out!r}, '--quiet']))")
        drivers = [subprocess.Popen([sys.executable, "-c", code, str(delay)], stderr=subprocess.PIPE, text=True)
                   for delay in delays]
        outcomes = [(driver.wait(timeout=120), driver.stderr.read()) for driver in drivers]
        for driver in drivers:
            driver.stderr.close()
        assert any(status == 1 for status, _ in outcomes), outcomes
        for status, message in outcomes:
            assert status == 1 and message == "" or status == 2 and "is in use by another batch" in message, outcomes
        after = folder_bytes(out)
        assert {name: data for name, data in after.items() if name != engine.LOCK_FILE} == \
            {name: data for name, data in before.items() if name != engine.LOCK_FILE}
    print(f"figure: batch: concurrent drivers into one folder: {len(outcomes)} started, "
          f"{sum(status == 2 for status, _ in outcomes)} refused in the last round")
