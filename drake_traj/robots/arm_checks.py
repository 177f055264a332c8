"""The checks of a custom 6-axis arm's data, one set for both ways in: a scenario's
``!CustomArm``/``!DhArm`` (:mod:`drake_traj.robots.custom`, fields ``robot.lower``, ...) and
:class:`~drake_traj.robots.chain_arm.ChainArm` and its constructors (arguments ``lower_limits``,
...). Each takes the name of its field and raises a DrakeTrajError (a ValueError) naming it (and
the index: ``masses[2]``); they run before a model is written or parsed, so Drake never sees
data it would refuse.
"""

from __future__ import annotations

import numpy as np

from collections.abc import Callable, Sequence

from drake_traj.errors import DrakeTrajError
from drake_traj.robots import ROBOT_NAMES
from drake_traj.validation import finite_array, invalid, real_array

__all__ = ["ARM_JOINTS", "arm_name", "inertia_rows", "joint_vector", "link_radius", "matrix", "missing_limit",
           "payload", "ranges", "scenario_message", "unbounded_joints"]

ARM_JOINTS = 6  # a custom arm has six revolute joints
# [m] The most a DH arm's links may reach end to end (the sum over its rows of sqrt(d² + a²)):
# the largest industrial arms reach under 5 m; lengths beyond this are a typo (mm for m) whose
# model the cell check would sample without end.
MAX_REACH = 20.0
MAX_LINK_RADIUS = 1.0  # [m] a link capsule's radius
_NAME_CHARACTERS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-")


def joint_vector(value, name: str, unit: str, *, required: bool, positive: bool = False) -> np.ndarray | None:
    """``value`` as ARM_JOINTS finite numbers (positive if asked), None when empty (or None) and
    not ``required``."""
    array = real_array([] if value is None else value, name, unit)
    if array.size == 0:
        if required:
            raise invalid(name, f"{name} is missing: a custom arm needs {ARM_JOINTS} values [{unit}]")
        return None
    array = finite_array(array, name, unit, shape=(ARM_JOINTS,))
    if positive and np.any(array <= 0):
        j = int(np.flatnonzero(array <= 0)[0])
        raise invalid(name, f"{name}[{j}] must be positive [{unit}], got {array[j]:g}", j)
    return array


def matrix(value, name: str, unit: str, columns: int, *, required: bool) -> np.ndarray | None:
    """``value`` as a finite (ARM_JOINTS, columns) array, None when empty (or None) and not
    ``required``."""
    rows = real_array([] if value is None else value, name, unit, "a list of rows of numbers")
    if rows.size == 0:
        if required:
            raise invalid(name, f"{name} is missing: a custom arm needs {ARM_JOINTS} rows of {columns} numbers [{unit}]")
        return None
    if rows.shape != (ARM_JOINTS, columns):
        raise invalid(name, f"{name} must be {ARM_JOINTS} rows of {columns} numbers [{unit}], got shape {rows.shape}")
    bad = np.argwhere(~np.isfinite(rows))
    if len(bad):
        i, k = (int(v) for v in bad[0])
        raise invalid(name, f"{name}[{i}][{k}] must be finite [{unit}], got {rows[i, k]}", i, k)
    return rows


def arm_name(value, name: str, *, plain: bool = True) -> str:
    """A custom arm's name: a non-empty text (``plain``: letters, digits, _ and -, at most 64
    characters, as it goes into a written model), not a known robot's (:data:`ROBOT_NAMES`:
    runs and exports are told apart by the name)."""
    if not isinstance(value, str) or not value or (
            plain and (len(value) > 64 or not set(value) <= _NAME_CHARACTERS)):
        what = "a plain name (letters, digits, _ and -; at most 64 characters)" if plain else "a non-empty text"
        raise invalid(name, f"{name} must be {what}, got {value!r:.80}")
    if value in ROBOT_NAMES:
        raise invalid(name, f"{name} {value!r} is a known robot's name (runs and exports are told apart by it); "
                            "choose another")
    return value


def payload(value, name: str) -> float | None:
    """A rated payload [kg]: finite and > 0, or None (not rated)."""
    if value is None:
        return None
    rating = finite_array(value, name, "kg", shape=())
    if rating <= 0:
        raise invalid(name, f"{name} must be positive [kg] (leave it out for an arm without a rating), "
                            f"got {float(rating):g}")
    return float(rating)


def ranges(lower: np.ndarray | None, upper: np.ndarray | None, lower_name: str, upper_name: str) -> None:
    """Each joint's upper limit above its lower limit [rad]; the error names ``upper_name[j]``."""
    if lower is not None and upper is not None and np.any(lower >= upper):
        j = int(np.flatnonzero(lower >= upper)[0])
        raise invalid(upper_name, f"{upper_name}[{j}] = {upper[j]:g} rad must be above {lower_name}[{j}] = "
                                  f"{lower[j]:g} rad", j)


def inertia_rows(value, name: str) -> np.ndarray | None:
    """``value`` as (ARM_JOINTS, 6) rows [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] [kg m²] of physical
    inertias (principal moments >= 0 meeting the triangle inequality), None when empty."""
    rows = matrix(value, name, "kg m^2", 6, required=False)
    for i, (ixx, iyy, izz, ixy, ixz, iyz) in enumerate([] if rows is None else rows):
        moments = np.linalg.eigvalsh([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        tolerance = 1e-9 * max(float(np.max(np.abs(moments))), 1e-12)
        if moments[0] < -tolerance or moments[2] > moments[0] + moments[1] + tolerance:
            raise invalid(name, f"{name}[{i}] is not a rigid body's inertia: its principal moments "
                                f"{', '.join(f'{m:.6g}' for m in moments)} kg m^2 must be >= 0 and each at most the sum "
                                "of the other two", i)
    return rows


def link_radius(value, name: str) -> float:
    """The links' capsule radius [m]: finite and > 0."""
    radius = finite_array(value, name, "m", shape=())
    if radius <= 0:
        raise invalid(name, f"{name} must be positive [m], got {float(radius):g}")
    if radius > MAX_LINK_RADIUS:
        raise invalid(name, f"{name} = {float(radius):g} m is above the {MAX_LINK_RADIUS:g} m a link's capsule may have")
    return float(radius)


def dh_reach(table: np.ndarray, name: str) -> None:
    """Refuse a DH table (rows [d, a, alpha, offset]) whose links reach more than
    :data:`MAX_REACH` end to end, at its largest length ``name[i][k]``."""
    lengths = np.abs(table[:, :2])
    reach = float(np.sum(np.hypot(lengths[:, 0], lengths[:, 1])))
    if reach > MAX_REACH:
        i, k = (int(v) for v in np.unravel_index(np.argmax(lengths), lengths.shape))
        raise invalid(name, f"{name}: the links reach {reach:.4g} m end to end (the sum of sqrt(d^2 + a^2) over the rows), "
                            f"above the {MAX_REACH:g} m a model may reach; the longest is {name}[{i}][{k}] = "
                            f"{table[i, k]:g} m ({'d' if k == 0 else 'a'}): lengths are in metres", i, k)


# a limit's unit, for the messages of missing_limit
_LIMIT_UNITS = dict(lower_limits="rad", upper_limits="rad", velocity_limits="rad/s", acceleration_limits="rad/s^2",
                    effort_limits="N m")
_RANGE = ("lower_limits", "upper_limits")


def _keyword(key: str) -> str:
    return f"{key}="


def unbounded_joints(values, joint_names: Sequence[str]) -> tuple[str, ...]:
    """The names of the joints whose ``values`` (a model's per-joint limits) are not finite: a
    continuous joint's range (±inf), a joint without a speed or torque limit."""
    return tuple(str(name) for name, value in zip(joint_names, np.asarray(values, dtype=float)) if not np.isfinite(value))


def missing_limit(key: str, arm: str, unbounded: Sequence[str] = (), *,
                  name: Callable[[str], str] = _keyword, given_by: str = "the arguments give") -> DrakeTrajError:
    """The error for a custom arm's limit ``key`` (``lower_limits``, ...) that neither its model
    nor ``given_by`` it (``"the arguments give"``), at the field ``(key,)``. ``unbounded``: the joints the model leaves
    without a finite value (:func:`unbounded_joints`; for the position range: continuous joints);
    ``name(key)``: how the message tells the user to give it (``lower_limits=`` for Python;
    ``robot.lower`` for a scenario, :func:`scenario_message`). The error keeps ``key``, ``arm`` and
    ``unbounded`` (attributes ``limit``, ``arm``, ``unbounded_joints``) so that a caller can word
    it in its own terms."""
    unit = _LIMIT_UNITS.get(key, "")
    give = f"{name(_RANGE[0])} and {name(_RANGE[1])}" if key in _RANGE else name(key)
    count = f"{ARM_JOINTS} values each" if key in _RANGE else f"{ARM_JOINTS} values"
    if unbounded:
        joints = ", ".join(repr(j) for j in unbounded)
        plural = "s" if len(unbounded) > 1 else ""
        if key in _RANGE:
            why = (f"its model gives joint{plural} {joints} no finite position range (a continuous joint, or limits "
                   "of ±inf), which a planner needs")
        else:
            why = f"its model gives joint{plural} {joints} no finite {key.replace('_limits', '').replace('_', ' ')} limit"
        message = f"{key} missing for the custom arm {arm!r}: {why}; give {give} ({count} [{unit}])"
    else:
        message = (f"{key} missing for the custom arm {arm!r}: neither its model nor {given_by} it "
                   f"(give {give}, {count} [{unit}])")
    error = DrakeTrajError(message, field=(key,))
    error.limit, error.arm, error.unbounded_joints = key, arm, tuple(unbounded)
    return error


def scenario_message(error: DrakeTrajError, name: Callable[[str], str]) -> str:
    """``error``'s text as a scenario's reader needs it: a :func:`missing_limit` error worded
    again with the scenario's fields (``name("lower_limits")`` -> ``robot.lower``); any other
    error's text as it is."""
    key = getattr(error, "limit", None)
    if key is None:
        return str(error)
    reworded = missing_limit(key, error.arm, error.unbounded_joints, name=name, given_by="the scenario gives")
    return str(reworded).replace(f"{key} missing", "missing", 1)
