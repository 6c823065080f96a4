"""A spec's runs on Dask distributed: a local cluster of one single-threaded worker process per core by default,
or the cluster at ``address`` (``dask scheduler`` and ``dask worker`` processes, each started from the workspace).

Each run is one task, ``execute_run``, which starts the run process (``mbot_batch.run``) in a session of its own
and hands back what it saw with its logs; the driver writes every file, so workers need no shared folder. A task
whose worker dies is rescheduled by Dask (up to ``distributed.scheduler.allowed-failures`` times); a run that
crashed, hung or was killed is submitted again as the spec's ``retries`` say. Finished runs are skipped when the
same spec runs again into the same folder.
"""
import glob
import hashlib
import json
import logging
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import uuid

from . import report
from .results import (RETRIED, load_result, log_tail, verdict, write_attempt_logs, write_json, write_result,
                      write_summary)
from .run import TOKEN_VARIABLE, kill_token
from .spec import Run, Spec

# A run process that outlives its own timeout by this much is killed from the task (it enforces its timeout
# itself; the margin covers its clean stop).
RUN_PROCESS_MARGIN_SECONDS = 30.0
# Each log a run hands back is cut to its last part: the driver holds every result, and a chatty node's log
# would otherwise travel whole.
LOG_CAP_BYTES = 200_000
CLOSE_TIMEOUT_SECONDS = 3
# Dask's own upkeep, slowed for tasks that are one long subprocess each: the worker's statistical profiler
# (every 10 ms), the memory and system monitors (100 ms, 500 ms) and the event-loop tick (20 ms) kept an idle
# local cluster of two workers at 0.077 cores, about 4 % of the example's CPU; with these, 0.011.
QUIET_UPKEEP = {"distributed.worker.profile.enabled": False,
                "distributed.worker.memory.monitor-interval": "1s",
                "distributed.admin.system-monitor.interval": "2s",
                "distributed.admin.tick.interval": "1s"}


def batch_token(out: str) -> str:
    """The prefix of every run token of the batch writing into ``out``."""
    return "mbot-batch-" + hashlib.sha1(os.path.realpath(out).encode()).hexdigest()[:10]


def execute_run(run_data: dict, token_prefix: str, options=()) -> dict:
    """On a worker (or here, for a rerun): one run in its own process and temporary folder; returns the run
    process's record (raw.json) with the worker's name and the run's logs. ``options``: the run process's
    --gui, --rviz."""
    run = Run.from_dict(run_data)
    folder = tempfile.mkdtemp(prefix=f"mbot-batch-{run.run_id}-")
    # Unique per execution: a rescheduled run must not be killed by the clean-up of its earlier execution.
    token = f"{token_prefix}:{run.run_id}:{uuid.uuid4().hex[:8]}"
    try:
        run_file = os.path.join(folder, "run.json")
        with open(run_file, "w") as stream:
            json.dump(run_data, stream)
        with open(os.path.join(folder, "run_process.log"), "w") as log:
            command = [sys.executable, "-m", "mbot_batch.run", run_file, folder, "--parent", str(os.getpid()), *options]
            process = subprocess.Popen(command, env=dict(os.environ, **{TOKEN_VARIABLE: token}), stdout=log,
                                       stderr=subprocess.STDOUT, start_new_session=True)
        try:
            process.wait(timeout=run.timeout + RUN_PROCESS_MARGIN_SECONDS)
        except subprocess.TimeoutExpired:
            kill_token(token)
            process.wait()
        try:
            with open(os.path.join(folder, "raw.json")) as stream:
                raw = json.load(stream)
        except (OSError, ValueError):
            raw = {"timeout": run.timeout, "timed_out": False, "metrics": {},
                   "error": f"the run process ended with status {process.returncode} before its record"}
        raw["worker"] = _worker_name()
        raw["logs"] = _collect_logs(folder)
        return raw
    finally:
        kill_token(token)
        shutil.rmtree(folder, ignore_errors=True)


def _worker_name() -> str:
    try:
        from distributed import get_worker
        return get_worker().address
    except ValueError:  # not on a worker: a rerun
        return socket.gethostname()


def _collect_logs(folder: str) -> dict:
    logs = {}
    paths = sorted(glob.glob(os.path.join(folder, "logs", "*")) + [os.path.join(folder, "run_process.log")]
                   + glob.glob(os.path.join(folder, "ros_home", "log", "**", "*.log"), recursive=True))
    for path in paths:
        if os.path.isfile(path) and not os.path.islink(os.path.dirname(path)):  # not again through log/latest
            with open(path, "rb") as stream:
                stream.seek(max(0, os.path.getsize(path) - LOG_CAP_BYTES))
                name = os.path.relpath(path, folder).replace(os.sep, "__").removeprefix("logs__")
                logs[name] = stream.read().decode(errors="replace")
    return logs


def result_record(run: Run, raw: dict, spec: Spec, attempt: int, logs: dict) -> dict:
    """The run's result.json: the verdict, its metrics, timing, where it ran, the CPU seconds of its processes and
    the tail of its main log."""
    main_log = next((logs[name] for name in ("scenario.log", "rostest.log") if logs.get(name, "").strip()), "")
    tail = log_tail(main_log or logs.get("launch.log", "") or logs.get("run_process.log", ""))
    metrics = raw.get("metrics") or {}
    return {"run_id": run.run_id, "scenario": run.scenario, **verdict(raw, spec.scenarios[run.scenario].checks),
            "metrics": metrics, "attempts": attempt, "wall_seconds": raw.get("wall_seconds", 0.0),
            "sim_seconds": metrics.get("sim_time", ""), "worker": raw.get("worker", ""),
            "cpu_seconds": raw.get("cpu_seconds", {}), "log_tail": tail}


def connect(address, workers):
    """A Dask client on the cluster at ``address``, or on a local cluster of ``workers`` processes."""
    import dask
    from distributed import Client, LocalCluster
    if address:
        return Client(address, timeout=30), None
    # One thread per worker process: a run is a process tree of its own, and a killed worker loses one run. The
    # workers take the upkeep settings from their nannies, which read them here.
    with dask.config.set(QUIET_UPKEEP):
        cluster = LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_batch(spec: Spec, out: str, address: str = None, workers: int = None, quiet: bool = False,
              runs=None) -> int:
    """Runs what is not finished in ``out`` yet of ``runs`` (default: all the spec's); writes summary.csv and
    report.html. 0 when every run passed, 1 when some did not, 130 when interrupted."""
    from distributed import as_completed
    from tqdm import tqdm
    runs = runs or spec.runs()
    os.makedirs(out, exist_ok=True)
    shutil.copyfile(spec.path, os.path.join(out, "spec.yaml"))
    write_json(os.path.join(out, "batch.json"), {"spec": os.path.abspath(spec.path), "name": spec.name,
                                                  "runs": [run.run_id for run in runs]})
    results = {run.run_id: result for run in runs if (result := load_result(out, run.run_id))}
    todo = [run for run in runs if run.run_id not in results]
    say = (lambda text: None) if quiet else (lambda text: print(f"mbot batch: {text}", file=sys.stderr, flush=True))
    say(f"{len(runs)} runs in {out}: {len(results)} finished before (skipped), {len(todo)} to run")
    token = batch_token(out)
    started = time.monotonic()
    client = cluster = None
    try:
        if todo:
            client, cluster = connect(address, workers)
            say(f"on {len(client.scheduler_info(n_workers=-1)['workers'])} Dask workers at "
                f"{client.scheduler.address}")
            _run_all(client, todo, spec, out, token, results, as_completed,
                     tqdm(total=len(todo), unit="run", file=sys.stderr, disable=quiet, dynamic_ncols=True))
    except KeyboardInterrupt:
        kill_token(token)  # this machine's runs first: the embedded cluster's are all here
        if client is not None:
            try:
                client.run(kill_token, token, wait=True, timeout=CLOSE_TIMEOUT_SECONDS)
            except Exception:  # noqa: BLE001 - workers already gone are fine: their runs die with them
                pass
        say("interrupted: every run stopped; run the same command again to resume")
        return 130
    finally:
        _close(client, cluster)
        kill_token(token)
    write_summary(os.path.join(out, "summary.csv"), runs, results)
    report.write(os.path.join(out, "report.html"), spec.name, runs, results,
                 wall_seconds=time.monotonic() - started if todo else None)
    failing = sum(result["status"] != "passed" for result in results.values())
    say(f"{len(results) - failing} of {len(runs)} runs passed; report: {os.path.join(out, 'report.html')}")
    return 1 if failing else 0


def _run_all(client, todo, spec, out, token, results, as_completed, progress):
    from distributed import KilledWorker
    futures = {}

    def submit(run: Run, attempt: int):
        future = client.submit(execute_run, run.to_dict(), token, key=f"{run.run_id}-attempt-{attempt}",
                               pure=False)
        futures[future] = (run, attempt)
        return future

    pending = as_completed([submit(run, 1) for run in todo])
    counts = {"passed": 0, "failed": 0, "error": 0, "timeout": 0}
    with progress:
        for future in pending:
            run, attempt = futures.pop(future)
            try:
                raw = future.result()
            except KilledWorker as error:
                raw = {"error": f"its workers died while running it ({error})", "metrics": {},
                       "timeout": run.timeout}
            logs = raw.pop("logs", {})
            write_attempt_logs(out, run.run_id, attempt, logs)
            result = result_record(run, raw, spec, attempt, logs)
            if result["status"] in RETRIED and attempt <= spec.retries:
                progress.write(f"mbot batch: {run.run_id} attempt {attempt}: {result['status']}: {result['reason']};"
                               " retrying")
                pending.add(submit(run, attempt + 1))
                continue
            write_result(out, run, result)
            results[run.run_id] = result
            counts[result["status"]] += 1
            progress.set_postfix_str(" ".join(f"{key} {value}" for key, value in counts.items() if value),
                                     refresh=False)
            progress.update(1)


def _close(client, cluster):
    for closable in (client, cluster):
        if closable is not None:
            try:
                closable.close(timeout=CLOSE_TIMEOUT_SECONDS)
            except Exception:  # noqa: BLE001 - a cluster that does not close in time is killed with this process
                pass
