"""A run's processes without ROS: every one of them killed, from its run process and from outside, whatever its
environment, signal handling or parentage; each captured log capped at its head and tail, every metric line read."""
import os
import signal
import subprocess
import sys
import uuid

import pytest
from mbot_batch import engine, results, run
from ros_processes import processes_named, wait_until

SCENARIOS = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "scenarios")
sys.path.insert(0, SCENARIOS)
from hang import HOSTILE_CHILDREN  # noqa: E402 - the scenarios' folder is no package

# A stand-in for a run process: its run's subreaper, with the hostile children of the hanging scenario; on a line
# "own" it kills its run as a run process does at its end, and exits. (The marker comes in its environment: only
# the children's command lines hold it.)
FAKE_RUN = f"""
import os, sys, time
sys.path.insert(0, {SCENARIOS!r})
from hang import start_hostile_children
from mbot_batch.run import TOKEN_VARIABLE, become_subreaper, kill_token
become_subreaper()
start_hostile_children(os.environ["MARKER"])
print("ready", flush=True)
if sys.stdin.readline().strip() == "own":
    kill_token(os.environ[TOKEN_VARIABLE], caller=os.getpid())
    sys.exit(0)
time.sleep(1000)
"""


@pytest.mark.parametrize("killer", ["its run process", "the driver"])
def test_every_process_of_a_run_is_killed_whatever_its_environment(killer):
    marker = f"mbot-batch-test-child-{uuid.uuid4().hex[:8]}"
    token = f"mbot-batch-test-{uuid.uuid4().hex[:8]}"
    fake = subprocess.Popen([sys.executable, "-c", FAKE_RUN], env=dict(os.environ, MBOT_BATCH_RUN=token, MARKER=marker),
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, start_new_session=True)
    try:
        assert fake.stdout.readline() == "ready\n"
        wait_until(lambda: len(processes_named(marker)) == HOSTILE_CHILDREN, 10, "the run's children")
        if killer == "its run process":
            fake.stdin.write("own\n")
            fake.stdin.flush()
            assert fake.wait(timeout=10) == 0
        else:  # as the driver's Ctrl-C and a worker's timeout do: by the token, the run process with the rest
            assert run.kill_token(token) >= 2
            assert fake.wait(timeout=10) == -signal.SIGKILL
        wait_until(lambda: not processes_named(marker), 5, "every child of the run to be gone")
    finally:
        for pid in processes_named(marker):
            os.kill(pid, signal.SIGKILL)
        fake.kill()
        fake.wait()


def test_a_batch_kills_its_own_runs_only():
    """Two batches (or a batch and a rerun) into one folder: one's clean-up leaves the other's runs alone."""
    out = "/tmp/mbot-batch-test-out"
    first, second = engine.batch_token(out), engine.batch_token(out)
    assert first != second and first.startswith(engine.folder_token(out)) and len(first) == len(second)
    sleeper = subprocess.Popen(["sleep", "60"], env=dict(os.environ, MBOT_BATCH_RUN=f"{first}:run-1:0"))
    try:
        run.kill_token(second)
        assert sleeper.poll() is None, "another batch's clean-up killed this batch's run"
        run.kill_token(first)
        assert sleeper.wait(timeout=5) == -signal.SIGKILL
    finally:
        sleeper.kill()
        sleeper.wait()


def test_a_captured_log_keeps_its_head_and_tail_and_every_metric(tmp_path, monkeypatch):
    for variable in ("ROS_HOME", "ROS_LOG_DIR", "TMPDIR", "PYTHONUNBUFFERED"):
        monkeypatch.setenv(variable, os.environ.get(variable, ""))  # restored after: RunProcesses sets them
    chatty = ("import sys; out = sys.stdout.buffer; out.write(b'metric first 1.5\\n')\n"
              "for index in range(20000): out.write(b'x' * 1023 + b'\\n')\n"
              "out.write(b'metric middle -2.5\\n' + b'y' * 3000000 + b'\\n')\n"
              "for index in range(20000): out.write(b'z' * 1023 + b'\\n')\n"
              "out.write(b'metric last inf')")
    printed = (b"metric first 1.5\n" + (b"x" * 1023 + b"\n") * 20000 + b"metric middle -2.5\n" + b"y" * 3000000
               + b"\n" + (b"z" * 1023 + b"\n") * 20000 + b"metric last inf")
    processes = run.RunProcesses(a_run(), str(tmp_path), gui=False, rviz=False)
    assert processes.start([sys.executable, "-c", chatty], "scenario.log").wait(timeout=60) == 0
    processes.close_logs()
    kept = (tmp_path / "logs" / "scenario.log").read_bytes()
    dropped = len(printed) - run.LOG_HEAD_BYTES - run.LOG_TAIL_BYTES
    assert kept == printed[:run.LOG_HEAD_BYTES] + run.left_out(dropped) + printed[-run.LOG_TAIL_BYTES:]
    assert f"{dropped} bytes of output left out here".encode() in kept
    print(f"figure: batch: a scenario's {len(printed)} bytes of output kept in {len(kept)}")
    metrics = results.parse_metrics(processes.captured["scenario.log"].metric_lines())
    assert metrics == {"first": 1.5, "middle": -2.5, "last": float("inf")}
    assert run.read_capped(str(tmp_path / "logs" / "scenario.log")) == kept


def a_run():
    from mbot_batch.spec import Run
    return Run(run_id="drive-1", scenario="drive", values={"seed": 0}, labels={"seed": "0"}, repetition=0, seed=0,
               launch_path="/l.launch", python_path="/s.py", rostest_path=None, launch_args={}, ros_params={},
               scenario_params={}, timeout=10.0)
