"""A spec's runs on Dask distributed: a local cluster of one single-threaded worker process per core by default,
or the cluster at ``address`` (``dask scheduler`` and ``dask worker`` processes, each started from the workspace).

Each run is one task, ``execute_run``, which starts the run process (``mbot_batch.run``) in a session of its own
and hands back what it saw with its logs; the driver writes every file, so workers need no shared folder. A task
whose worker dies is rescheduled by Dask (up to ``distributed.scheduler.allowed-failures`` times); a run that
crashed, hung or was killed is submitted again as the spec's ``retries`` say. Finished runs are skipped when the
same spec runs again into the same folder.
"""
import fcntl
import glob
import hashlib
import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import uuid
from contextlib import contextmanager

from . import report
from .results import (RETRIED, load_result, log_tail, recorded, verdict, write_attempt_logs, write_bytes,
                      write_json, write_result, write_summary)
from .run import TOKEN_VARIABLE, kill_token, read_capped
from .spec import Run, Spec

# A run process that outlives its own timeout by this much is killed from the task (it enforces its timeout
# itself; the margin covers its clean stop).
RUN_PROCESS_MARGIN_SECONDS = 30.0
CLOSE_TIMEOUT_SECONDS = 3
LOCK_FILE = "batch.lock"
# Dask's own upkeep, slowed for tasks that are one long subprocess each: the worker's statistical profiler
# (every 10 ms), the memory and system monitors (100 ms, 500 ms) and the event-loop tick (20 ms) kept an idle
# local cluster of two workers at 0.077 cores, about 4 % of the example's CPU; with these, 0.011.
QUIET_UPKEEP = {"distributed.worker.profile.enabled": False,
                "distributed.worker.memory.monitor-interval": "1s",
                "distributed.admin.system-monitor.interval": "2s",
                "distributed.admin.tick.interval": "1s"}


def folder_token(out: str) -> str:
    """The prefix of every run token of every batch and rerun writing into ``out``."""
    return "mbot-batch-" + hashlib.sha1(os.path.realpath(out).encode()).hexdigest()[:10]


def batch_token(out: str) -> str:
    """The prefix of every run token of one batch (or rerun) writing into ``out``: unique, so that its clean-up
    kills no other's runs. All have one length, so that none is the prefix of another."""
    return f"{folder_token(out)}-{uuid.uuid4().hex[:12]}"


class FolderInUse(RuntimeError):
    """Another batch writes into the output folder; the message is one line naming the folder and that batch."""


@contextmanager
def folder_lock(out: str):
    """The output folder for this batch alone while the block runs: an exclusive flock on OUT/batch.lock, which the
    kernel releases with its process however that ends (so a killed driver leaves no stale lock). The file says who
    holds it, for the refusal; it is never removed (a batch that opened it before its removal would lock a file
    that the next batch no longer sees)."""
    os.makedirs(out, exist_ok=True)
    handle = os.open(os.path.join(out, LOCK_FILE), os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(handle, 1000, 0).decode(errors="replace").strip() or "whose holder is not written yet"
            raise FolderInUse(f"{out} is in use by another batch ({holder}): wait for it to end, or give another "
                              "-o") from None
        holder = (f"pid {os.getpid()} on {socket.gethostname()} since {time.strftime('%Y-%m-%d %H:%M:%S')}"
                  .encode())
        os.ftruncate(handle, 0)
        os.pwrite(handle, holder, 0)
        yield
    finally:
        os.close(handle)


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
            # Cut to its head and tail: the driver holds every result, and a chatty node's log would travel whole.
            name = os.path.relpath(path, folder).replace(os.sep, "__").removeprefix("logs__")
            logs[name] = read_capped(path).decode(errors="replace")
    return logs


def result_record(run: Run, raw: dict, spec: Spec, attempt: int, logs: dict) -> dict:
    """The run's result.json: the verdict, its metrics, timing, where it ran, the CPU seconds of its processes and
    the tail of its main log."""
    main_log = next((logs[name] for name in ("scenario.log", "rostest.log") if logs.get(name, "").strip()), "")
    tail = log_tail(main_log or logs.get("launch.log", "") or logs.get("run_process.log", ""))
    metrics = {name: recorded(value) for name, value in (raw.get("metrics") or {}).items()}
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
    report.html. 0 when every run passed, 1 when some did not, 130 when interrupted (at any point: every file it
    writes is put in place whole). Raises FolderInUse when another batch writes into ``out``."""
    runs = runs or spec.runs()
    say = (lambda text: None) if quiet else (lambda text: print(f"mbot batch: {text}", file=sys.stderr, flush=True))
    token = batch_token(out)
    with folder_lock(out):
        client = cluster = None
        try:
            with open(spec.path, "rb") as source:
                write_bytes(os.path.join(out, "spec.yaml"), source.read())
            write_json(os.path.join(out, "batch.json"), {"spec": os.path.abspath(spec.path), "name": spec.name,
                                                          "runs": [run.run_id for run in runs]})
            results = {run.run_id: result for run in runs if (result := load_result(out, run.run_id))}
            todo = [run for run in runs if run.run_id not in results]
            say(f"{len(runs)} runs in {out}: {len(results)} finished before (skipped), {len(todo)} to run")
            started = time.monotonic()
            if todo:
                from tqdm import tqdm
                client, cluster = connect(address, workers)
                say(f"on {len(client.scheduler_info(n_workers=-1)['workers'])} Dask workers at "
                    f"{client.scheduler.address}")
                _run_all(client, todo, spec, out, token, results,
                         tqdm(total=len(todo), unit="run", file=sys.stderr, disable=quiet, dynamic_ncols=True))
                _close(client, cluster)
                client = cluster = None
                kill_token(token)
            write_summary(os.path.join(out, "summary.csv"), runs, results)
            report.write(os.path.join(out, "report.html"), spec.name, runs, results,
                         wall_seconds=time.monotonic() - started if todo else None)
        except KeyboardInterrupt:
            # A second Ctrl-C does not cut the clean-up short (it takes CLOSE_TIMEOUT_SECONDS at most).
            previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
            try:
                _stop(client, cluster, token)
            finally:
                signal.signal(signal.SIGINT, previous)
            say("interrupted: every run stopped; run the same command again to resume")
            return 130
        except BaseException:
            _stop(client, cluster, token)
            raise
    failing = sum(result["status"] != "passed" for result in results.values())
    say(f"{len(results) - failing} of {len(runs)} runs passed; report: {os.path.join(out, 'report.html')}")
    return 1 if failing else 0


def _stop(client, cluster, token):
    """Every run of the batch killed: this machine's first (the embedded cluster's are all here), then each
    worker's own (``Client.run``), and the cluster closed."""
    kill_token(token)
    if client is not None:
        try:
            client.run(kill_token, token, wait=True, timeout=CLOSE_TIMEOUT_SECONDS)
        except Exception:  # noqa: BLE001 - workers already gone are fine: their runs die with them
            pass
    _close(client, cluster)
    kill_token(token)


def _run_all(client, todo, spec, out, token, results, progress):
    from distributed import KilledWorker, as_completed
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
            except Exception as error:  # noqa: BLE001 - the task itself failed on its worker (no temporary folder)
                raw = {"error": f"its task failed: {type(error).__name__}: {error}", "metrics": {},
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
