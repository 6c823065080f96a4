"""The one home of the speed figures: ``./mbot bench`` records every figure it prints into ``results.json`` (with
the date, the machine and its raw PyBullet real-time factor), and the speed table of the bridge's README is
generated from that file (by the bench, or ``python3 docs/generate_docs.py``; a test fails when the two differ).

Each bench script reports through ``report()``: it prints ``FIGURE: VALUE`` as before and, when the bench runs
them (``MBOT_BENCH_RECORD`` names a file), appends the figure there, so that a figure reaches the README only
through what the bench printed. ``--short`` (every script's, through ``parse_arguments()``) runs every row at
smoke-test sizes and durations, and each row's figure then starts with ``SHORT_MARK``.
"""
import argparse
import datetime
import json
import os
import platform
import time
from typing import Dict, List

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results.json")
README = os.path.join(HERE, "..", "README.md")
RECORD_ENV = "MBOT_BENCH_RECORD"
TABLE_START = "<!-- speed table: generated from src/mbot_sim_bridge/bench/results.json by docs/generate_docs.py -->"
TABLE_END = "<!-- end of the speed table -->"
SHORT_MARK = "[short mode] "
SHORT_NOTE = ("figures of `./mbot bench --short` (every row at smoke-test sizes and durations): they show that "
              "the rows run, not the speed; a full `./mbot bench` on a quiet machine replaces them")
_short = False


def parse_arguments(parser: argparse.ArgumentParser, short_help: str) -> argparse.Namespace:
    """The script's arguments with ``--short`` added; in short mode every figure reported is marked so."""
    global _short
    parser.add_argument("--short", action="store_true", help=short_help + " (a smoke test; the figures mean little)")
    args = parser.parse_args()
    _short = args.short
    return args


def report(figure: str, value: str):
    """Print one figure and record it for results.json when the bench runs this script."""
    if _short:
        figure = SHORT_MARK + figure
    print(f"{figure}: {value}", flush=True)
    path = os.environ.get(RECORD_ENV)
    if path:
        with open(path, "a") as record:
            record.write(json.dumps({"figure": figure, "value": value}) + "\n")


def wait_for_clock(clock: list, count: int, timeout: float = 60.0):
    """Until ``clock`` (the /clock messages a subscriber appends) holds ``count`` of them: a real-time factor
    needs two inside its window."""
    deadline = time.monotonic() + timeout
    while len(clock) < count:
        if time.monotonic() > deadline:
            raise RuntimeError(f"no /clock within {timeout:g} s")
        time.sleep(0.05)


def recorded(path: str) -> List[Dict[str, str]]:
    if not os.path.exists(path):
        return []
    with open(path) as record:
        return [json.loads(line) for line in record if line.strip()]


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            return next(line.split(":", 1)[1].strip() for line in cpuinfo if line.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def write_results(path: str, rows: List[Dict[str, str]], raw_pybullet: float, short: bool):
    results = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d"),
        "machine": f"{cpu_model()}, {os.cpu_count()} cores",
        "raw_pybullet_real_time_factor": round(raw_pybullet, 2),
        "note": SHORT_NOTE if short else "figures of a full `./mbot bench`",
        "rows": rows,
    }
    with open(path, "w") as stream:
        json.dump(results, stream, indent=1, ensure_ascii=False)
        stream.write("\n")


def speed_table(results: dict) -> str:
    """The README's block: where the figures come from, then one row per figure."""
    lines = [TABLE_START, "",
             f"Measured {results['date']} on {results['machine']} (raw PyBullet: "
             f"{results['raw_pybullet_real_time_factor']:g}x real time); {results['note']}.", "",
             "| Figure | Value |", "|--------|-------|"]
    lines += [f"| {row['figure']} | {row['value'].replace('|', '/')} |" for row in results["rows"]]
    return "\n".join(lines + ["", TABLE_END])


def with_table(text: str, results: dict) -> str:
    start, end = text.index(TABLE_START), text.index(TABLE_END) + len(TABLE_END)
    return text[:start] + speed_table(results) + text[end:]


def load(path: str = RESULTS) -> dict:
    with open(path) as stream:
        return json.load(stream)
