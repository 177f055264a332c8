"""Input checks shared by the package. Every error names the argument, the expected form (with
the unit) and what was given: a :class:`~drake_traj.errors.DrakeTrajError` (a ValueError, cause
INVALID, ``field`` the argument's path and index) for a malformed value (text, a boolean or None
where a number is expected, a wrong shape, a number out of range), a TypeError for an object of
the wrong type (:func:`instance_of`, :func:`path_argument`, :func:`callable_or_none`)."""

import numbers
import os
from pathlib import Path

import numpy as np

from drake_traj.errors import DrakeTrajError, field_text, joint_label


def field_of(name: str, *index: int) -> tuple:
    """The field path of an argument named ``name`` (``"speed_override.times"`` ->
    ``("speed_override", "times")``) followed by ``index``; empty where ``name`` is a phrase, not
    a field (``"path parameter s"``)."""
    parts = name.split(".")
    return tuple(parts) + index if all(part.isidentifier() for part in parts) else ()


def invalid(name: str, message: str, *index: int) -> DrakeTrajError:
    """The error for the argument or field ``name`` (at ``index``): its text is ``message``."""
    return DrakeTrajError(message, field=field_of(name, *index))


def at_field(error: ValueError, name: str, *index: int) -> DrakeTrajError:
    """``error`` (about a value) passed on at the field ``name`` (and ``index``), its text
    prefixed with the field (``points[2]: ...``), its cause kept."""
    field = field_of(name, *index)
    message = f"{field_text(field) or name}: {error}"
    if isinstance(error, DrakeTrajError):
        return error.relocated(field, message)
    return DrakeTrajError(message, field=field)


def _first_non_number(value):
    """``(entry,)`` for the first entry of ``value`` (a number or nested lists, tuples and arrays
    of numbers) that is not a real number (text, a boolean, None, ...); None if every entry is.
    ``np.array(..., dtype=float)`` would read the text '1.5' as 1.5 and True as 1.0."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "iuf":
            return None
        value = value.tolist()
    if isinstance(value, (bool, np.bool_, str, bytes)):
        return (value,)
    if isinstance(value, numbers.Real):
        return None
    if isinstance(value, (list, tuple, range)):
        for item in value:
            found = _first_non_number(item)
            if found is not None:
                return found
        return None
    return (value,)


def real_array(value, name: str, unit: str, what: str = "a real number or an array of real numbers") -> np.ndarray:
    """``value`` (a number or nested lists of numbers) as a float array (copy); ValueError naming
    ``name`` and saying it must be ``what`` for text, booleans, None or ragged rows. Non-finite
    entries are kept."""
    found = _first_non_number(value)
    if found is not None:
        raise invalid(name, f"{name} must be {what} [{unit}], found {type(found[0]).__name__} {found[0]!r:.40}"
                         + ("" if found[0] is value else f" in {value!r:.80}"))
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        reason = str(exc)
        if "inhomogeneous" in reason:  # a ragged list: say which row is off
            lengths = [len(row) if hasattr(row, "__len__") else 1 for row in value]
            reason = f"its rows must have the same length, got lengths {lengths}"
        raise invalid(name, f"{name} must be an array of real numbers [{unit}]: {reason}") from exc


def real_scalar(value, name: str, unit: str, *, minimum: float = -np.inf, strict: bool = False) -> float:
    """``value`` as a finite float >= ``minimum`` (> with ``strict``), else ValueError naming ``name``."""
    array = real_array(value, name, unit, "a real number")
    if array.size != 1:
        raise invalid(name, f"{name} must be a real number [{unit}], got shape {array.shape}")
    number = float(array.reshape(-1)[0])
    if not np.isfinite(number):
        raise invalid(name, f"{name} must be finite [{unit}], got {number}")
    if number < minimum or (strict and number == minimum):
        raise invalid(name, f"{name} must be {'>' if strict else '>='} {minimum:g} [{unit}], got {number}")
    return number


def positive_scalar(value, name: str, unit: str) -> float:
    """A finite float > 0 [unit]."""
    return real_scalar(value, name, unit, minimum=0.0, strict=True)


def nonnegative_scalar(value, name: str, unit: str) -> float:
    """A finite float >= 0 [unit]."""
    return real_scalar(value, name, unit, minimum=0.0)


def tracking_tolerance_check(tracking_tolerance, clearance) -> None:
    """Refuse a ``tracking_tolerance`` [m] larger than half the cell's ``clearance`` [m] (equal
    is allowed; None, no tracking check, passes): the cell check keeps at least half the
    clearance everywhere along the planned reference (:mod:`drake_traj.cell.clearance`), so an arm
    that may stray further than that from its reference may touch what the check cleared. A
    :class:`~drake_traj.errors.DrakeTrajError` (a ValueError, ``field`` ``("tracking_tolerance",)``)
    naming both in mm and what to change; also for either value malformed."""
    if tracking_tolerance is None:
        return
    tolerance = positive_scalar(tracking_tolerance, "tracking_tolerance", "m")
    clearance = nonnegative_scalar(clearance, "cell.clearance", "m")
    half = 0.5 * clearance
    if tolerance <= half * (1 + 1e-9):
        return
    lower = (f"lower tracking_tolerance to at most {1e3 * half:g} mm or " if half > 0 else "")
    raise invalid("tracking_tolerance", f"tracking_tolerance = {1e3 * tolerance:g} mm is larger than half the cell's "
                  f"clearance ({1e3 * half:g} mm of cell.clearance = {1e3 * clearance:g} mm): the check before the "
                  "motion keeps half the clearance along the planned reference, and an arm that strays further "
                  f"from it may touch what was checked clear; {lower}raise cell.clearance to at least "
                  f"{2e3 * tolerance:g} mm")


# The bounds of a run's times and pace (docs/troubleshooting.md): every run ends, and
# its log (1 ms samples by default, about 0.3 kB each) fits in memory.
MAX_RUN_DURATION = 600.0  # [s] max_duration, and the preflight's horizon: 10 minutes of simulated motion
MAX_SETTLE_TIME = 60.0  # [s] settle_time, the run after the planner finishes
MIN_STEP = 1e-5  # [s] plant.time_step, simulator.max_step_size, a planner's update period: 100 kHz at most
REALTIME_RATES = (0.1, 1000.0)  # a live run's pace (--rate, simulator.target_realtime_rate; 0: as fast as it goes)


def run_duration(value, name: str = "max_duration") -> float:
    """A run's ``max_duration`` [s]: finite, > 0 and at most :data:`MAX_RUN_DURATION`."""
    value = positive_scalar(value, name, "s")
    if value > MAX_RUN_DURATION:
        raise invalid(name, f"{name} must be at most {MAX_RUN_DURATION:g} s (the longest run simulated and logged), "
                            f"got {value:g} s")
    return value


def settle_duration(value, name: str = "settle_time") -> float:
    """A run's ``settle_time`` [s]: finite, >= 0 and at most :data:`MAX_SETTLE_TIME`."""
    value = nonnegative_scalar(value, name, "s")
    if value > MAX_SETTLE_TIME:
        raise invalid(name, f"{name} must be at most {MAX_SETTLE_TIME:g} s after the planner finishes, got {value:g} s")
    return value


def step_size(value, name: str) -> float:
    """A simulation step or update period [s]: finite and at least :data:`MIN_STEP` (a finer
    one would take hours for a run of seconds)."""
    value = positive_scalar(value, name, "s")
    if value < MIN_STEP:
        raise invalid(name, f"{name} must be at least {MIN_STEP:g} s (a finer step would take hours to simulate a "
                            f"run of seconds), got {value:g} s")
    return value


def realtime_rate(value, name: str) -> float:
    """A simulator's ``target_realtime_rate``: 0 (as fast as it goes) or within
    :data:`REALTIME_RATES` (a slower pace would leave a run hanging for hours)."""
    value = nonnegative_scalar(value, name, "times real time")
    low, high = REALTIME_RATES
    if value != 0 and not low <= value <= high:
        raise invalid(name, f"{name} must be 0 (as fast as it goes) or from {low:g} to {high:g} times real time, "
                            f"got {value:g}")
    return value


def finite_array(value, name: str, unit: str, *, shape: tuple | None = None) -> np.ndarray:
    """``value`` as a float array (copy) of ``shape`` (any if None) with finite entries."""
    array = real_array(value, name, unit)
    if shape is not None and array.shape != shape:
        raise invalid(name, f"{name} must have shape {shape} [{unit}], got shape {array.shape}")
    require_finite(array, name, unit)
    return array


def positive_vector(value, name: str, n: int) -> np.ndarray:
    """A per-joint limit: a scalar (every joint) or n values, all finite and > 0."""
    array = real_array(value, name, "per joint")
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,):
        raise invalid(name, f"{name} must be a scalar or have shape ({n},), got shape {array.shape}")
    bad = ~np.isfinite(array) | (array <= 0.0)
    if np.any(bad):
        j = int(np.argmax(bad))
        raise invalid(name, f"{name}[{j}] ({joint_label(j)}) must be finite and > 0, got {array[j]}", j)
    return array


def limit_or_default(value, default, name: str, n: int) -> np.ndarray:
    """A per-joint limit from a config (:func:`positive_vector`), ``default`` when it is empty."""
    if value is None or np.size(value) == 0:
        if default is None or not np.all(np.isfinite(default)):
            raise invalid(name, f"{name} must be given: the robot has no default {name.replace('_', ' ')}")
        value = default
    return positive_vector(value, name, n)


def whole_number(value, name: str, *, minimum: int, maximum: int | None = None) -> int:
    """``value`` as an int in [``minimum``, ``maximum``] (an int, or a float with no fraction),
    else ValueError naming ``name``."""
    within = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
    if (isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) or not np.isfinite(value)
            or value != int(value)):
        raise invalid(name, f"{name} must be a whole number {within}, got {value!r:.80}")
    if int(value) < minimum or (maximum is not None and int(value) > maximum):
        raise invalid(name, f"{name} must be a whole number {within}, got {int(value)}")
    return int(value)


def flag(value, name: str) -> bool:
    """``value`` if it is True or False (a Python or NumPy bool), else ValueError naming ``name``
    (a truthy text such as 'no' is not a yes)."""
    if not isinstance(value, (bool, np.bool_)):
        raise invalid(name, f"{name} must be True or False, got {type(value).__name__} {value!r:.80}")
    return bool(value)


def instance_of(value, expected: type | tuple[type, ...], name: str, hint: str = ""):
    """``value`` if it is an ``expected`` (a type or a tuple of types), else TypeError naming
    ``name``, the expected type(s), what was given and ``hint``."""
    if not isinstance(value, expected):
        names = " or ".join(t.__name__ for t in (expected if isinstance(expected, tuple) else (expected,)))
        raise TypeError(f"{name} must be a {names}, got {type(value).__name__}: {value!r:.80}{hint}")
    return value


def path_argument(value, name: str, what: str = "file") -> Path:
    """``value`` (a str or ``os.PathLike``) as a Path, else TypeError naming ``name``."""
    if not isinstance(value, (str, os.PathLike)) or value == "":
        raise TypeError(f"{name} must be a {what} path (str or Path), got {type(value).__name__}: {value!r:.80}")
    return Path(value)


def callable_or_none(value, name: str, signature: str):
    """``value`` if it is None or callable, else TypeError naming ``name`` and the call expected."""
    if value is not None and not callable(value):
        raise TypeError(f"{name} must be a function {signature} or None, got {type(value).__name__}: {value!r:.80}")
    return value


def log_period_check(log_period: float, time_step: float) -> None:
    """Raise ValueError unless ``log_period`` [s] is a whole multiple of the plant's ``time_step``
    [s] (the loggers sample the plant's steps). Both already checked positive."""
    steps = log_period / time_step
    if abs(steps - round(steps)) > 1e-9 * steps or round(steps) < 1:
        raise invalid("log_period", f"log_period must be a whole multiple of plant.time_step = {time_step} s "
                         f"(the loggers sample the plant's steps), got {log_period} s")


def float_array(value, name: str, unit: str) -> np.ndarray:
    """``value`` as a float array (copy) as numpy reads it (the text '1.5' is 1.5), else
    ValueError naming ``name``; :func:`real_array` is the stricter check."""
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise invalid(name, f"{name} must be an array of real numbers [{unit}]: {exc}") from exc


def require_finite(array: np.ndarray, name: str, unit: str = "") -> None:
    """A :class:`DrakeTrajError` at the first non-finite entry of ``array`` (its index, and
    ``unit`` where given)."""
    if not np.all(np.isfinite(array)):
        bad = np.argwhere(~np.isfinite(np.atleast_1d(array)))[0]
        index = [int(i) for i in bad] if array.ndim else []
        where = f"[{', '.join(map(str, index))}]" if index else ""
        value = np.atleast_1d(array)[tuple(bad)]
        raise invalid(name, f"{name}{where} must be finite{f' [{unit}]' if unit else ''}, got {value}", *index)


def require_positive(array: np.ndarray, name: str, unit: str = "") -> None:
    """A :class:`DrakeTrajError` at the first entry of ``array`` that is not > 0: its index and
    joint (the last axis counts joints), and ``unit`` where given."""
    if np.any(array <= 0.0):
        unit = f" [{unit}]" if unit else ""
        if array.ndim == 0:
            raise invalid(name, f"{name} must be > 0{unit}, got {float(array)}")
        index = [int(i) for i in np.argwhere(array <= 0.0)[0]]
        raise invalid(name, f"{name}[{', '.join(map(str, index))}] ({joint_label(index[-1])}) must be > 0{unit}, "
                            f"got {float(array[tuple(index)])}", *index)


def joint_bound(value, name: str, num_joints: int, unit: str) -> np.ndarray:
    """A per-joint value: a scalar (every joint) or shape (num_joints,), finite (:func:`real_array`)."""
    array = real_array(value, name, unit)
    if array.ndim == 0:
        array = np.full(num_joints, float(array))
    elif array.shape != (num_joints,):
        raise invalid(name, f"{name} must be a scalar or have shape ({num_joints},), got shape {array.shape}")
    require_finite(array, name)
    return array


def joint_limit(value, name: str, num_joints: int, unit: str) -> np.ndarray:
    """A per-joint limit: as :func:`joint_bound`, and > 0."""
    array = joint_bound(value, name, num_joints, unit)
    require_positive(array, name)
    return array


def joint_limit_with_unit(value, name: str, unit: str, num_joints: int) -> np.ndarray:
    """A per-joint limit: a scalar (every joint) or shape (num_joints,), finite and > 0, read as
    numpy reads it (:func:`float_array`); the messages give ``unit``."""
    array = float_array(value, name, unit)
    if array.ndim != 0 and array.shape != (num_joints,):
        raise invalid(name, f"{name} must be a scalar or have shape ({num_joints},) [{unit}], got shape {array.shape}")
    require_finite(array, name, unit)
    array = np.broadcast_to(array, (num_joints,)).copy()
    require_positive(array, name, unit)
    return array
