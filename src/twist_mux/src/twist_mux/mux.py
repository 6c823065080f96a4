"""twist_mux's selection, computed as upstream's C++ (ros-teleop/twist_mux, noetic-devel) computes it, without
rospy so that it is tested with plain times.

- An input or a lock is heard at ``stamp`` (upstream starts it at time 0, not "never"); with a timeout > 0 it
  has expired once ``now - stamp > timeout``; a timeout of 0 never expires.
- A lock is locked while it has expired or its last Bool was true. The lock priority is the highest priority of
  the locked locks (0 when none is).
- An input is masked while it has expired or its priority is below the lock priority, so a lock silences the
  inputs strictly below its own priority (a lock equal to an input's priority lets it through: upstream's
  example config gives its "pause" lock the joystick's priority so that it does not block the joystick).
- A message passes when its input is the first, in the parameter list's order, of the unmasked inputs with
  the highest priority above 0 (a priority-0 input never passes, as upstream). Nothing is sent between messages.

One addition: when a lock masks the input whose message passed last, one zero Twist goes out, so a base stops
at once rather than after its controller's command timeout (upstream sends nothing more; the e-stop of a
Clearpath control.launch relies on diff_drive_controller's 0.25 s timeout).
"""
import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

MIN_PRIORITY, MAX_PRIORITY = 0, 255
TWIST_FIELDS = ("linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z")


@dataclass
class Handle:
    """An input (``kind`` "velocity") or a lock (``kind`` "lock") from the ``topics`` or ``locks`` list."""
    kind: str
    name: str
    topic: str
    timeout: float
    priority: int
    stamp: float = 0.0
    locked_value: bool = False

    def expired(self, now: float) -> bool:
        return self.timeout > 0.0 and now - self.stamp > self.timeout

    def locked(self, now: float) -> bool:
        return self.expired(now) or self.locked_value

    def masked(self, now: float, lock_priority: int) -> bool:
        return self.expired(now) or self.priority < lock_priority

    def describe(self, now: float, lock_priority: int) -> str:
        """Upstream's diagnostics text for this handle."""
        state = (("locked" if self.locked(now) else "free") if self.kind == "lock"
                 else ("masked" if self.masked(now, lock_priority) else "unmasked"))
        return f" {state} (listening to {self.topic} @ {self.timeout:f}s with priority #{self.priority})"


def parse_handles(kind: str, entries, parameter: str) -> Tuple[List[Handle], List[str]]:
    """The handles of a ``topics`` or ``locks`` parameter, and one error line per entry left out. Upstream
    stops at the first bad entry (ROS_FATAL, the rest unread); here only the bad entry is left out."""
    if entries is None:
        return [], []
    if not isinstance(entries, list):
        return [], [f"parameter {parameter}: expected a list of entries (name, topic, timeout, priority), "
                    f"got {type(entries).__name__}"]
    handles, errors = [], []
    for index, entry in enumerate(entries):
        where = f"parameter {parameter}[{index}]"
        try:
            handles.append(_handle(kind, entry, where))
        except ValueError as error:
            errors.append(f"{where}: {error}; entry left out")
    return handles, errors


def _handle(kind: str, entry, where: str) -> Handle:
    if not isinstance(entry, dict):
        raise ValueError(f"expected a dictionary with name, topic, timeout and priority, got {entry!r}")
    missing = [key for key in ("name", "topic", "timeout", "priority") if key not in entry]
    if missing:
        raise ValueError(f"missing {', '.join(missing)}")
    name, topic = entry["name"], entry["topic"]
    for key, value in (("name", name), ("topic", topic)):
        if not isinstance(value, str) or not value:
            raise ValueError(f"{key} must be a non-empty string, got {value!r}")
    timeout = entry["timeout"]
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or math.isnan(timeout) or timeout < 0:
        raise ValueError(f"timeout must be a number of seconds >= 0 (0: never expires), got {timeout!r}")
    priority = entry["priority"]
    if isinstance(priority, bool) or not isinstance(priority, (int, float)) or not float(priority).is_integer():
        raise ValueError(f"priority must be an integer in [{MIN_PRIORITY}, {MAX_PRIORITY}], got {priority!r}")
    # Upstream clamps the priority into [0, 255].
    return Handle(kind, name, topic, float(timeout), int(min(max(priority, MIN_PRIORITY), MAX_PRIORITY)))


def non_finite_field(values: Sequence[float]) -> Optional[Tuple[str, float]]:
    """The first of a Twist's six values (in TWIST_FIELDS order) that is NaN or infinite, with its value."""
    return next(((field, value) for field, value in zip(TWIST_FIELDS, values) if not math.isfinite(value)), None)


# m/s and rad/s beyond any vehicle (the simulator's own cap on set speeds): still forwarded, as upstream does, since
# the base's limits apply, but said once so that a unit or scale mistake upstream of the mux shows.
HUGE_VALUE = 1.0e4


def huge_field(values: Sequence[float]) -> Optional[Tuple[str, float]]:
    """The first of a Twist's six finite values beyond HUGE_VALUE in magnitude, with its value."""
    return next(((field, value) for field, value in zip(TWIST_FIELDS, values) if abs(value) > HUGE_VALUE), None)


class TwistMux:
    def __init__(self, inputs: Sequence[Handle], locks: Sequence[Handle]):
        self.inputs = list(inputs)
        self.locks = list(locks)
        self._passing: Optional[Handle] = None  # the input whose message passed last, until a lock stops it

    def lock_priority(self, now: float) -> int:
        return max((lock.priority for lock in self.locks if lock.locked(now)), default=MIN_PRIORITY)

    def selected(self, now: float) -> Optional[Handle]:
        lock_priority = self.lock_priority(now)
        best, best_priority = None, MIN_PRIORITY
        for handle in self.inputs:
            if not handle.masked(now, lock_priority) and handle.priority > best_priority:
                best, best_priority = handle, handle.priority
        return best

    def on_twist(self, handle: Handle, now: float) -> bool:
        """A message arrived on ``handle`` at ``now``: True when it passes to ``cmd_vel_out``. Upstream compares
        the names, so inputs that share a name pass together."""
        handle.stamp = now
        best = self.selected(now)
        passes = best is not None and best.name == handle.name
        if passes:
            self._passing = handle
        return passes

    def on_lock(self, lock: Handle, value: bool, now: float):
        lock.stamp = now
        lock.locked_value = bool(value)

    def stop_due(self, now: float) -> bool:
        """True once when a lock has come to mask the input that was passing (the zero Twist is then due)."""
        passing = self._passing
        if passing is None:
            return False
        if passing.expired(now):
            self._passing = None
            return False
        if passing.priority < self.lock_priority(now):
            self._passing = None
            return True
        return False

    def status(self, now: float) -> List[Tuple[str, str]]:
        """Upstream's diagnostics key/values (its loop time and data age are never measured there: always 0)."""
        lock_priority = self.lock_priority(now)
        values = [("velocity " + handle.name, handle.describe(now, lock_priority)) for handle in self.inputs]
        values += [("lock " + lock.name, lock.describe(now, lock_priority)) for lock in self.locks]
        values += [("current priority", str(lock_priority)), ("loop time in [sec]", "0"),
                   ("data age in [sec]", "0")]
        return values
