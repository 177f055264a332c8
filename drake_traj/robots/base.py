"""Shared machinery of the papers' point-placing robots (seed 001's three, seed 002's 4-DOF):
model file lookup, joint limits, reach checks with errors naming the point and the reason, and
the closed-form inverse kinematics wrapper. Subclasses (frozen dataclasses) give the dimensions,
limits, ``fk``, ``jacobian``, ``bias`` and ``_ik_raw``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import ClassVar

import numpy as np

LIMIT_TOL = 1e-12  # slack on joint limits [rad or m]


def point_array(position) -> np.ndarray:
    array = np.asarray(position, dtype=float)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"positions must have shape (..., 3) [m], got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError("positions must be finite")
    return array


def joint_vectors(q, size: int, name: str = "q") -> np.ndarray:
    """``q`` as a float array of shape (..., size), or ValueError naming ``name``."""
    array = np.asarray(q, dtype=float)
    if array.ndim == 0 or array.shape[-1] != size:
        raise ValueError(f"{name} must have shape (..., {size}), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite")
    return array


def format_point(point) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in point) + "]"


def stack_columns(columns) -> np.ndarray:
    return np.stack(np.broadcast_arrays(*columns), axis=-1)


class PointRobot:
    """Shared behaviour; subclasses are frozen dataclasses with the dimensions and limits."""

    name: ClassVar[str]
    model_file: ClassVar[str]
    joint_names: ClassVar[tuple[str, ...]]
    joint_types: ClassVar[tuple[str, ...]]  # "revolute" [rad] or "prismatic" [m]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    velocity_limit: tuple[float, ...]
    effort_limit: tuple[float, ...]

    base_frame: ClassVar[str] = "base"
    tool_frame: ClassVar[str] = "tool0"

    # ---- model file -------------------------------------------------------------------------
    def model_path(self) -> Path:
        """Absolute path of the robot's URDF shipped with the package (``models/<model_file>``)."""
        path = Path(str(resources.files("drake_traj.models").joinpath(self.model_file)))
        if not path.is_file():
            raise ValueError(f"{self.name} model file not found: {path}")
        return path

    # ---- per-robot kinematics (subclasses) --------------------------------------------------
    def fk(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """Position of ``tool0`` in the base frame [m], shape (..., 3)."""
        raise NotImplementedError

    def jacobian(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """J(q) = d fk / dq, shape (..., 3, n)."""
        raise NotImplementedError

    def bias(self, q, qd) -> np.ndarray:  # pragma: no cover - abstract
        """dJ/dt(q, qd) qd: the tool acceleration when qdd = 0 [m/s^2], shape (..., 3)."""
        raise NotImplementedError

    def singularity_measure(self, q) -> np.ndarray:  # pragma: no cover - abstract
        """In [0, 1]; zero exactly where J(q) is singular."""
        raise NotImplementedError

    def _ik_raw(self, p: np.ndarray):  # pragma: no cover - abstract
        """(q, reasons): IK of (N, 3) points, q of shape (N, n), with NaN rows where the closed form has no solution,
        and a list of (index, reason) for the domain errors found."""
        raise NotImplementedError

    @property
    def num_joints(self) -> int:
        return len(self.joint_names)

    # ---- limits ------------------------------------------------------------------------------
    @property
    def lower_limits(self) -> np.ndarray:
        return np.array(self.lower, dtype=float)

    @property
    def upper_limits(self) -> np.ndarray:
        return np.array(self.upper, dtype=float)

    def within_limits(self, q, tol: float = LIMIT_TOL) -> np.ndarray:
        """Whether each joint vector of ``q`` (..., n) is within the position limits."""
        q = joint_vectors(q, self.num_joints)
        return np.all((q >= self.lower_limits - tol) & (q <= self.upper_limits + tol), axis=-1)

    def _unit(self, k: int) -> str:
        return "rad" if self.joint_types[k] == "revolute" else "m"

    # ---- inverse kinematics -------------------------------------------------------------------
    def reach_problems(self, positions) -> list[tuple[int, str]]:
        """All out-of-reach points of ``positions`` (..., 3) as (flat index, reason), index order."""
        p = point_array(positions).reshape(-1, 3)
        return self._solve(p)[1]

    def is_reachable(self, positions) -> np.ndarray:
        """Boolean array (...) : True where :meth:`ik` has a solution within the joint limits."""
        p = point_array(positions)
        ok = np.ones(p.shape[:-1], dtype=bool).reshape(-1)
        for index, _ in self._solve(p.reshape(-1, 3))[1]:
            ok[index] = False
        return ok.reshape(p.shape[:-1])

    def reach_check(self, positions, label: str = "point", times=None) -> None:
        """Raise ValueError for the first out-of-reach point of ``positions`` (..., 3).

        The message names the robot, the point's flat index (and time, if ``times`` of the same
        flat length is given), the point, the reason and how many points fail in all.
        """
        p = point_array(positions).reshape(-1, 3)
        problems = self._solve(p)[1]
        if problems:
            raise ValueError(self._message(p, problems, label, times))

    def _message(self, p, problems, label, times) -> str:
        index, reason = problems[0]
        at = "" if times is None else f" (t = {float(np.ravel(times)[index]):.6g} s)"
        more = "" if len(problems) == 1 else f"; {len(problems)} of {len(p)} {label}s are out of reach"
        return (
            f"{label} {index}{at} at {format_point(p[index])} m is out of reach of the {self.name} robot: "
            f"{reason}{more}"
        )

    def _solve(self, p: np.ndarray):
        q, problems = self._ik_raw(p)
        bad = {index for index, _ in problems}
        lo, hi = self.lower_limits, self.upper_limits
        for k in range(self.num_joints):
            beyond = (q[:, k] < lo[k] - LIMIT_TOL) | (q[:, k] > hi[k] + LIMIT_TOL)  # NaN: False
            outside = np.flatnonzero(beyond)
            for index in outside:
                index = int(index)
                if index in bad:
                    continue
                bad.add(index)
                unit = self._unit(k)
                problems.append(
                    (index, f"{self.joint_names[k]} = {q[index, k]:.6g} {unit} is beyond its limits "
                            f"[{lo[k]:.6g}, {hi[k]:.6g}] {unit}")
                )
        problems.sort(key=lambda item: item[0])
        return q, problems

    def ik(self, position, label: str = "point", times=None) -> np.ndarray:
        """Closed-form inverse kinematics (the subclass's ``_ik_raw``), checked against the limits.

        Args:
            position: tool positions [m], shape (..., 3).
            label, times: only for the error message (see :meth:`reach_check`).

        Returns:
            Joint vectors, shape (..., n), on the branch documented in the robot's module.

        Raises:
            ValueError: a point out of reach (index and reason in the message).
        """
        p = point_array(position)
        flat = p.reshape(-1, 3)
        q, problems = self._solve(flat)
        if problems:
            raise ValueError(self._message(flat, problems, label, times))
        return q.reshape(p.shape[:-1] + (self.num_joints,))
