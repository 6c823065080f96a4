"""What a Python scenario uses: its run's parameters and a way to report metrics.

    from mbot_batch import scenario
    speed = scenario.parameters().get("speed", 0.2)    # the matrix's plain keys for this run
    ...                                                # drive the simulation with LockstepClient
    scenario.metric("distance", distance)             # printed as "metric distance 2.5" on stdout

A scenario runs as ``python3 FILE`` with ROS_MASTER_URI set to its run's own master; the launch file it drives
runs in lockstep with the run's seed. Its exit status counts: non-zero is a crashed run.
"""
import json
import os

PARAMETERS_VARIABLE = "MBOT_BATCH_PARAMETERS"


def parameters() -> dict:
    """The run's scenario parameters (empty outside a batch)."""
    return json.loads(os.environ.get(PARAMETERS_VARIABLE, "{}"))


def metric(name: str, value: float):
    """Report a metric. repr() prints a float's shortest exact form, so a rerun compares it bit for bit."""
    if not name or any(character.isspace() for character in name):
        raise ValueError(f"metric name {name!r} must be one word")
    print(f"metric {name} {float(value)!r}", flush=True)
