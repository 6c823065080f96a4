"""``./mbot batch SPEC.yaml [-o OUT] [--address ADDRESS] [--workers N] [--quiet]`` runs a spec's batch;
``./mbot batch rerun OUT RUN_ID [--gui] [--rviz]`` replays one run of it and compares its metrics bit for bit."""
import argparse
import os
import sys

from . import engine, launch_files, spec
from .results import load_result, load_run, run_folder, verdict, write_text


def main(argv=None):
    """The exit status: 130 on Ctrl-C at any point (the spec's check, the runs, the summary, the report)."""
    argv = sys.argv[1:] if argv is None else argv
    try:
        return rerun(argv[1:]) if argv and argv[0] == "rerun" else batch(argv)
    except KeyboardInterrupt:
        print("mbot batch: interrupted", file=sys.stderr)
        return 130


def batch(argv):
    parser = argparse.ArgumentParser(prog="mbot batch", description="Run a spec's seeded scenario batch on Dask "
                                     "distributed (./mbot batch rerun OUT RUN_ID replays one run).")
    parser.add_argument("spec", help="the batch spec (YAML)")
    parser.add_argument("-o", "--out", help="output folder (default out/batch/NAME); finished runs in it are skipped")
    parser.add_argument("--address", help="a Dask scheduler's address (tcp://HOST:8786); default: a local cluster")
    parser.add_argument("--workers", type=int, help="the local cluster's worker processes (default: one per core)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar or messages")
    args = parser.parse_args(argv)
    if args.workers is not None and args.workers < 1:
        parser.error("--workers must be at least 1")
    try:
        checked = spec.load(args.spec, launch_files.resolve)
    except spec.SpecError as error:
        print(f"mbot batch: {error}", file=sys.stderr)
        return 2
    out = args.out or os.path.join("out", "batch", checked.name)
    try:
        return engine.run_batch(checked, out, address=args.address, workers=args.workers, quiet=args.quiet)
    except engine.FolderInUse as error:
        print(f"mbot batch: {error}", file=sys.stderr)
        return 2


def rerun(argv):
    parser = argparse.ArgumentParser(prog="mbot batch rerun", description="Replay one run of a batch here and "
                                     "compare its metrics with the batch's, bit for bit.")
    parser.add_argument("out", help="the batch's output folder")
    parser.add_argument("run_id")
    parser.add_argument("--gui", action="store_true", help="show the simulator window (needs a DISPLAY)")
    parser.add_argument("--rviz", action="store_true", help="rviz with the lidar mbot's config beside the run")
    args = parser.parse_args(argv)
    recorded = load_result(args.out, args.run_id)
    if recorded is None:
        print(f"mbot batch rerun: {run_folder(args.out, args.run_id)} holds no finished run", file=sys.stderr)
        return 2
    run = load_run(args.out, args.run_id)
    print(f"mbot batch rerun: {run.run_id} ({recorded['status']} in the batch)", file=sys.stderr, flush=True)
    options = [flag for flag, wanted in (("--gui", args.gui), ("--rviz", args.rviz)) if wanted]
    raw = engine.execute_run(run.to_dict(), engine.batch_token(args.out), options)
    folder = os.path.join(args.out, "reruns", run.run_id)
    for name, text in raw.pop("logs").items():
        write_text(os.path.join(folder, name), text)
    checks = {check["metric"]: spec.Check(check["min"], check["max"]) for check in recorded["checks"]}
    outcome = verdict(raw, checks)
    print(f"status: {outcome['status']}" + (f" ({outcome['reason']})" if outcome["reason"] else ""))
    identical = True
    for name in sorted(set(recorded["metrics"]) | set(raw["metrics"])):
        before, now = recorded["metrics"].get(name), raw["metrics"].get(name)
        same = before is not None and now is not None and float(before).hex() == float(now).hex()
        identical &= same
        print(f"  {name}: {now!r} (batch: {before!r}) {'bit-identical' if same else 'DIFFERS'}")
    print(f"metrics {'bit-identical to' if identical else 'differ from'} the batch's; logs: {folder}")
    return 0 if identical else 1
