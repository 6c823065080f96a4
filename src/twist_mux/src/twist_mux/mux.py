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
from typing import Callable, List, Optional, Sequence, Tuple

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
    where: str = ""  # the entry it came from, "parameter ~topics[0] ('joy')", for the lines about it
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
    """The handles of a ``topics`` or ``locks`` parameter, and one error line per entry left out or priority
    clamped. Upstream stops at the first bad entry (ROS_FATAL, the rest unread); here only the bad entry is left
    out. An input whose name an earlier one has is left out too: upstream selects by name, so inputs of one name
    would pass together whatever their priorities (locks act each on its own, so theirs may repeat)."""
    if entries is None:
        return [], []
    if not isinstance(entries, list):
        return [], [f"parameter {parameter}: expected a list of entries (name, topic, timeout, priority), "
                    f"got {type(entries).__name__}"]
    handles, errors, first_of_name = [], [], {}
    for index, entry in enumerate(entries):
        where = f"parameter {parameter}[{index}]"
        try:
            handle = _handle(kind, entry, where, errors)
        except ValueError as error:
            errors.append(f"{where}: {error}; entry left out")
            continue
        if kind == "velocity" and handle.name in first_of_name:
            first = first_of_name[handle.name]
            errors.append(f"{where}: name {handle.name!r} is already that of {parameter}[{first}]; entry left out")
            continue
        first_of_name.setdefault(handle.name, index)
        handles.append(handle)
    return handles, errors


def _handle(kind: str, entry, where: str, errors: List[str]) -> Handle:
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
    where = f"{where} ({name!r})"
    clamped = int(min(max(priority, MIN_PRIORITY), MAX_PRIORITY))
    if clamped != priority:
        never = " (an input of priority 0 never passes)" if kind == "velocity" and clamped == MIN_PRIORITY else ""
        errors.append(f"{where}: priority {priority:g} is outside [{MIN_PRIORITY}, {MAX_PRIORITY}]; {clamped} is "
                      f"used, as upstream clamps it{never}")
    return Handle(kind, name, topic, float(timeout), clamped, where)


def check_topics(inputs: Sequence[Handle], locks: Sequence[Handle], output: str, resolve: Callable[[str], str]
                 ) -> Tuple[List[Handle], List[Handle], List[str]]:
    """The inputs and locks to subscribe, and one error line per input left out: an input on ``output`` (the
    resolved cmd_vel_out) would feed itself, each message passing out and in again as fast as the node runs; an
    input on a lock's topic cannot be told from it (one topic, one type; rospy would hand the lock the Twists, and
    upstream's roscpp throws at the second subscription, uncaught), and the input goes so that a lock is never lost.
    Topics compare as ``resolve`` (rospy.resolve_name: namespace and remappings) gives them."""
    lock_of_topic = {}
    for lock in locks:
        lock_of_topic.setdefault(resolve(lock.topic), lock)
    kept, errors = [], []
    for handle in inputs:
        topic = resolve(handle.topic)
        if topic == output:
            errors.append(f"{handle.where}: topic {topic} is cmd_vel_out, this node's output: the input would feed "
                          "itself; entry left out")
        elif topic in lock_of_topic:
            errors.append(f"{handle.where}: topic {topic} is also that of the lock {lock_of_topic[topic].where}, "
                          "which listens for std_msgs/Bool; the input is left out, the lock kept")
        else:
            kept.append(handle)
    return kept, list(locks), errors


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
