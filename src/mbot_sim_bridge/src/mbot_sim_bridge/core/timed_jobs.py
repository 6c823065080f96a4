"""Jobs gazebo_ros schedules from service calls (apply_body_wrench, apply_joint_effort): each acts before every
physics step whose start time lies in [start, start + duration] (a negative duration never ends, one of 0 acts
for the step at its start) and is dropped once the time passes its end, as upstream's schedulers run them on
world-update-begin."""
import sys
import threading
from typing import Callable, Generic, List, Optional, TypeVar

import numpy as np

from .errors import ModelError

# A job: anything with ``start`` and ``duration`` (s of sim time).
Job = TypeVar("Job")
# The largest start time and duration (s): what a ROS time or duration can carry (a uint32 or int32 of seconds), so
# every request through ROS passes, and a start of 1e308 s cannot overflow the loop's count of steps to it.
MAX_JOB_TIME = 2.0 ** 32


def check_window(what: str, start: float, duration: float):
    """ModelError for a start time or duration that is not finite or beyond MAX_JOB_TIME."""
    if not all(abs(value) <= MAX_JOB_TIME for value in (start, duration)):  # False for NaN too
        raise ModelError(f"{what}: start_time and duration must be finite and at most {MAX_JOB_TIME:g} s in size "
                         f"(what a ROS time holds); got start_time {start}, duration {duration}")


def acts_at(job, now: float) -> bool:
    return now >= job.start and (job.duration < 0 or now <= job.start + job.duration)


def ended_at(job, now: float) -> bool:
    return job.duration >= 0 and now > job.start + job.duration


class TimedJobs(Generic[Job]):
    """The scheduled jobs; requests arrive from ROS threads, the loop applies them."""

    def __init__(self):
        self._lock = threading.Lock()
        self._jobs: List[Job] = []

    def add(self, job: Job):
        with self._lock:
            self._jobs.append(job)

    def remove(self, matches: Callable[[Job], bool]):
        with self._lock:
            self._jobs = [job for job in self._jobs if not matches(job)]

    def pending(self) -> bool:
        return bool(self._jobs)

    def steps_until_next(self, now: float, step_size: float) -> Optional[int]:
        """1 while a job acts; the steps to the earliest start otherwise; None without jobs."""
        with self._lock:
            starts = [job.start for job in self._jobs]
        if not starts:
            return None
        steps = (min(starts) - now) / step_size - 1e-9
        if not steps < sys.maxsize:  # a start too far off to count in steps (1e308 s overflowed): not due
            return sys.maxsize
        return max(1, int(np.ceil(steps)))

    def acting(self, now: float) -> List[Job]:
        """The jobs that act in the step starting at ``now``, in the order they came; ended jobs are dropped."""
        with self._lock:
            acting = [job for job in self._jobs if acts_at(job, now)]
            self._jobs = [job for job in self._jobs if not ended_at(job, now)]
        return acting
