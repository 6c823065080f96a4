"""The batch's report page: one static HTML file with its matplotlib figures embedded (PNG, base64), free of ROS.

Pass rate per value of each matrix key, the distribution of each metric (its check's bounds drawn; values it cannot
draw, not finite or past matplotlib's range, listed below it), the failing runs with their ids, reasons and log
tails, and the slowest runs."""
import base64
import html
import io
from collections import defaultdict
from typing import Dict, List

from .results import finite, write_text
from .spec import Run

SLOWEST = 10
FIGURE_WIDTH = 9.0
BINS = 20
# matplotlib's axes overflow on values of about 1e308 (their span is not a float); a histogram of such values is
# not drawn but listed.
DRAWABLE = 1e300


def write(path: str, title: str, runs: List[Run], results: Dict[str, dict], wall_seconds: float = None):
    """Rendered first, then put in place whole: an interrupted report leaves the earlier one."""
    write_text(path, page(title, runs, results, wall_seconds))


def page(title: str, runs: List[Run], results: Dict[str, dict], wall_seconds: float = None) -> str:
    done = [run for run in runs if run.run_id in results]
    statuses = defaultdict(int)
    for run in done:
        statuses[results[run.run_id]["status"]] += 1
    figures = [figure for figure in (_pass_rates(done, results), _metric_distributions(done, results)) if figure]
    failing = [run for run in done if results[run.run_id]["status"] != "passed"]
    slowest = sorted(done, key=lambda run: results[run.run_id]["wall_seconds"], reverse=True)[:SLOWEST]
    summary = ", ".join(f"{count} {status}" for status, count in sorted(statuses.items()))
    timing = f"; this invocation took {wall_seconds:.0f} s" if wall_seconds else ""
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_e(title)}: batch report</title>",
             "<style>body{font-family:sans-serif;margin:2em;max-width:1100px}table{border-collapse:collapse}"
             "td,th{border:1px solid #ccc;padding:3px 8px;text-align:left;vertical-align:top}"
             "pre{font-size:11px;max-height:18em;overflow:auto;background:#f6f6f6}img{max-width:100%}"
             ".failed{color:#b00}.error,.timeout{color:#a60}</style></head><body>",
             f"<h1>{_e(title)}</h1><p>{len(done)} of {len(runs)} runs finished: {_e(summary) or 'none'}{timing}.</p>"]
    parts += [f"<h2>{_e(caption)}</h2><img alt='{_e(caption)}' src='data:image/png;base64,{image}'>"
              for caption, image in figures]
    undrawn = [(run, name, value) for run in done for name, value in sorted(results[run.run_id]["metrics"].items())
               if value is not None and not _drawable(value)]
    if undrawn:
        parts.append(f"<h2>Metrics not drawn ({len(undrawn)})</h2><p>Not finite, or beyond &plusmn;{DRAWABLE:g}."
                     "</p><table><tr><th>run id</th><th>metric</th><th>value</th><th>status</th></tr>")
        parts += [f"<tr><td><code>{_e(run.run_id)}</code></td><td>{_e(name)}</td><td>{_e(value)}</td>"
                  f"<td>{_e(results[run.run_id]['status'])}</td></tr>" for run, name, value in undrawn]
        parts.append("</table>")
    parts.append(f"<h2>Failing runs ({len(failing)})</h2>")
    if failing:
        parts.append("<table><tr><th>run id</th><th>status</th><th>reason</th><th>matrix</th><th>log tail</th></tr>")
        for run in failing:
            result = results[run.run_id]
            parts.append(f"<tr><td><code>{_e(run.run_id)}</code></td><td class='{result['status']}'>"
                         f"{result['status']}</td><td>{_e(result['reason'])}</td><td>{_e(_values(run))}</td>"
                         f"<td><details><summary>last lines</summary><pre>{_e(result['log_tail'])}</pre></details>"
                         "</td></tr>")
        parts.append("</table><p>Replay one: <code>./mbot batch rerun OUT RUN_ID [--gui] [--rviz]</code></p>")
    else:
        parts.append("<p>none</p>")
    parts.append("<h2>Slowest runs</h2><table><tr><th>run id</th><th>wall s</th><th>sim s</th><th>status</th>"
                 "<th>worker</th></tr>")
    for run in slowest:
        result = results[run.run_id]
        sim = result.get("sim_seconds")
        parts.append(f"<tr><td><code>{_e(run.run_id)}</code></td><td>{result['wall_seconds']:.1f}</td>"
                     f"<td>{f'{sim:.1f}' if finite(sim) else _e(sim)}</td><td>{result['status']}</td>"
                     f"<td>{_e(result.get('worker', ''))}</td></tr>")
    parts.append("</table></body></html>\n")
    return "\n".join(parts)


def _values(run: Run) -> str:
    return ", ".join(f"{key}={run.labels[key]}" for key in run.values)


def _png(figure) -> str:
    import matplotlib.pyplot as pyplot
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=80, bbox_inches="tight")
    pyplot.close(figure)
    return base64.b64encode(buffer.getvalue()).decode()


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot
    return pyplot


def _pass_rates(runs: List[Run], results: Dict[str, dict]):
    keys = list(dict.fromkeys(key for run in runs for key in run.values))
    if not keys:
        return None
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(len(keys), 1, figsize=(FIGURE_WIDTH, 2.2 * len(keys)), squeeze=False)
    for axis, key in zip(axes[:, 0], keys):
        passed, total = defaultdict(int), defaultdict(int)
        for run in runs:
            label = run.labels.get(key)
            total[label] += 1
            passed[label] += results[run.run_id]["status"] == "passed"
        labels = list(total)
        rates = [100.0 * passed[label] / total[label] for label in labels]
        axis.bar(range(len(labels)), rates, color=["#4a4" if rate == 100 else "#c84" for rate in rates])
        axis.set_xticks(range(len(labels)), labels, fontsize=8, rotation=45 if len(labels) > 8 else 0)
        axis.set_ylim(0, 105)
        axis.set_ylabel("% passed")
        axis.set_title(f"pass rate per {key}", fontsize=10)
    figure.tight_layout()
    return "Pass rate per parameter value", _png(figure)


def _metric_distributions(runs: List[Run], results: Dict[str, dict]):
    names = sorted({name for run in runs for name in results[run.run_id]["metrics"]})
    if not names:
        return None
    pyplot = _pyplot()
    columns = min(3, len(names))
    rows = -(-len(names) // columns)
    figure, axes = pyplot.subplots(rows, columns, figsize=(FIGURE_WIDTH, 2.6 * rows), squeeze=False)
    for axis in axes.flat[len(names):]:
        axis.set_visible(False)
    for axis, name in zip(axes.flat, names):
        values = [float(results[run.run_id]["metrics"][name]) for run in runs
                  if _drawable(results[run.run_id]["metrics"].get(name))]
        if values:
            axis.hist(values, bins=_bin_edges(values), color="#48c")
        bounds = {bound for run in runs for check in results[run.run_id]["checks"] if check["metric"] == name
                  for bound in (check["min"], check["max"]) if _drawable(bound)}
        for bound in bounds:
            axis.axvline(bound, color="#c33", linestyle="--")
        axis.set_title(name, fontsize=10)
        axis.set_ylabel("runs")
    figure.tight_layout()
    return "Metric distributions", _png(figure)


def _drawable(value) -> bool:
    return finite(value) and abs(value) <= DRAWABLE


def _bin_edges(values: List[float]):
    """numpy's default bins overflow on a span below about 1e-307 (bins per unit) and on one value of 1e300 (it
    widens it by 0.5); these edges are interpolated without taking the span, and a single value gets a bin of its
    own size around it."""
    import numpy
    low, high = min(values), max(values)
    steps = numpy.linspace(0.0, 1.0, BINS + 1)
    edges = numpy.unique(low * (1 - steps) + high * steps)
    if len(edges) < 2:
        half = max(0.5, abs(low) * 1e-3)
        edges = numpy.array([low - half, low + half])
    return edges


def _e(text) -> str:
    return html.escape(str(text), quote=True)
