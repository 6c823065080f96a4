#!/usr/bin/env python3
"""Throughput of ./mbot batch with 1 and then 2 local workers, measured in one run on the same runs of a spec
(default: the first 8 of the shipped example): runs per hour and simulated seconds per wall second, each
batch timed from the driver's start (the local cluster's start-up and every run's start-up counted).

    python3 src/mbot_batch/bench/bench_batch.py [--spec SPEC.yaml] [--runs N] [--workers 1 2]
"""
import argparse
import os
import sys
import tempfile
import time

from mbot_batch import engine, launch_files, spec
from mbot_batch.results import load_result

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "examples", "tour.yaml")


def cpu_per_run(results) -> str:
    """The runs' mean CPU seconds, in all and by process (the largest first)."""
    by_process = {}
    for result in results:
        for name, seconds in result.get("cpu_seconds", {}).items():
            by_process[name] = by_process.get(name, 0.0) + seconds / len(results)
    ranked = sorted(by_process.items(), key=lambda item: -item[1])
    cores = sum(by_process.values()) / (sum(result["wall_seconds"] for result in results) / len(results))
    return (f"{sum(by_process.values()):.2f} s, {cores:.2f} cores while it runs ("
            + ", ".join(f"{name} {seconds:.2f}" for name, seconds in ranked) + ")")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", default=EXAMPLE)
    parser.add_argument("--runs", type=int, default=8)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = parser.parse_args()
    batch = spec.load(args.spec, launch_files.resolve)
    runs = batch.runs()[:args.runs]
    rates = {}
    with tempfile.TemporaryDirectory(prefix="mbot-batch-bench-") as folder:
        for workers in args.workers:
            out = os.path.join(folder, f"workers-{workers}")
            started, driver_started = time.monotonic(), os.times()
            engine.run_batch(batch, out, workers=workers, quiet=True, runs=runs)
            wall = time.monotonic() - started
            driver = sum(os.times()[:2]) - sum(driver_started[:2])
            results = [load_result(out, run.run_id) for run in runs]
            sim = sum(result["sim_seconds"] or 0.0 for result in results)
            rates[workers] = len(runs) / wall * 3600
            print(f"figure: batch with {workers} worker(s): {len(runs)} runs in {wall:.1f} s = {rates[workers]:.0f} "
                  f"runs/hour, {sim / wall:.2f} sim s per wall s (runs alone: "
                  f"{sum(result['wall_seconds'] for result in results) / len(runs):.1f} s each)", flush=True)
            print(f"figure: batch with {workers} worker(s): CPU per run {cpu_per_run(results)}; the driver and "
                  f"Dask's scheduler {driver / len(runs):.2f} s per run", flush=True)
    if len(rates) > 1:
        first, *_, last = args.workers
        print(f"figure: batch {last} workers / {first}: {rates[last] / rates[first]:.2f}x the runs per hour")
    return 0


if __name__ == "__main__":
    sys.exit(main())
