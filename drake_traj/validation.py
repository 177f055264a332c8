"""Input checks shared by the planners. Every error is a ValueError naming the argument, the
expected form (with the unit) and what was given."""

import numpy as np


def real_scalar(value, name: str, unit: str, *, minimum: float = -np.inf, strict: bool = False) -> float:
    """``value`` as a finite float >= ``minimum`` (> with ``strict``), else ValueError naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a real number [{unit}]: {exc}") from exc
    if not np.isfinite(number):
        raise ValueError(f"{name} must be finite [{unit}], got {number}")
    if number < minimum or (strict and number == minimum):
        raise ValueError(f"{name} must be {'>' if strict else '>='} {minimum:g} [{unit}], got {number}")
    return number


def positive_scalar(value, name: str, unit: str) -> float:
    """A finite float > 0 [unit]."""
    return real_scalar(value, name, unit, minimum=0.0, strict=True)


def nonnegative_scalar(value, name: str, unit: str) -> float:
    """A finite float >= 0 [unit]."""
    return real_scalar(value, name, unit, minimum=0.0)


def finite_array(value, name: str, unit: str, *, shape: tuple | None = None) -> np.ndarray:
    """``value`` as a float array (copy) of ``shape`` (any if None) with finite entries."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an array of real numbers [{unit}]: {exc}") from exc
    if shape is not None and array.shape != shape:
        raise ValueError(f"{name} must have shape {shape} [{unit}], got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        bad = np.argwhere(~np.isfinite(np.atleast_1d(array)))[0]
        where = "" if array.ndim == 0 else "[" + ", ".join(str(int(i)) for i in bad) + "]"
        raise ValueError(f"{name}{where} must be finite [{unit}], got {np.atleast_1d(array)[tuple(bad)]}")
    return array


def positive_vector(value, name: str, n: int) -> np.ndarray:
    """A per-joint limit: a scalar (every joint) or n values, all finite and > 0."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a number or {n} numbers: {exc}") from exc
    if array.ndim == 0:
        array = np.full(n, float(array))
    if array.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got shape {array.shape}")
    bad = ~np.isfinite(array) | (array <= 0.0)
    if np.any(bad):
        j = int(np.argmax(bad))
        raise ValueError(f"{name}[{j}] (joint {j}) must be finite and > 0, got {array[j]}")
    return array


def limit_or_default(value, default, name: str, n: int) -> np.ndarray:
    """A per-joint limit from a config (:func:`positive_vector`), ``default`` when it is empty."""
    if value is None or np.size(value) == 0:
        if default is None or not np.all(np.isfinite(default)):
            raise ValueError(f"{name} must be given: the robot has no default {name.replace('_', ' ')}")
        value = default
    return positive_vector(value, name, n)


def instance_of(value, expected: type, name: str):
    """``value`` if it is an ``expected``, else TypeError naming ``name`` and what was given."""
    if not isinstance(value, expected):
        raise TypeError(f"{name} must be a {expected.__name__}, got {type(value).__name__}: {value!r:.80}")
    return value
