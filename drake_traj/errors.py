"""The package's exceptions and the record of a run that failed.

Every error drake_traj raises on purpose derives from :class:`DrakeTrajError`, itself a
``ValueError``: bad input (a malformed argument, an unreachable pose, infeasible limits) and a
task the planner cannot complete alike. A simulation that stops early keeps what it logged and
describes why in a :class:`Failure`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["DrakeTrajError", "Failure", "PlanningError", "SingularConfigurationError"]


class DrakeTrajError(ValueError):
    """Base of every error raised by drake_traj on purpose."""


class SingularConfigurationError(DrakeTrajError):
    """A kinematic quantity is undefined at this configuration or pose (a singular Jacobian,
    Euler-angle gimbal lock, an IK branch that does not exist there)."""


class PlanningError(DrakeTrajError):
    """The planner cannot complete the task: names the time, configuration and cause.

    Attributes:
        time: simulation time [s] (None if not known).
        configuration: q [rad] at that time (None if not known).
        cause: short machine-readable cause ("stall", "singular", "non-finite", "timeout", ...).
        partial: what was computed before the failure (dict of arrays), where a caller keeps it.
    """

    def __init__(self, message: str, *, time=None, configuration=None, cause: str = "", partial=None):
        where = ""
        if time is not None:
            where = f"at t = {float(time):.4f} s"
        if configuration is not None:
            where += f"{', ' if where else 'at '}q = {np.round(np.asarray(configuration, float), 4).tolist()}"
        super().__init__(f"{message} ({where})" if where else message)
        self.time = time
        self.configuration = None if configuration is None else np.array(configuration, dtype=float)
        self.cause = cause
        self.partial = partial


@dataclass(frozen=True)
class Failure:
    """Why a simulated run stopped before its planner finished.

    Attributes:
        cause: machine-readable cause: a :class:`PlanningError` cause ("stall", "singular", ...),
            "timeout" (``max_duration`` reached) or "error" (any other exception).
        message: the human-readable reason (for an exception: its type, time and text).
        time: simulation time of the failure [s], if known.
        configuration: the reference q at that time [rad], if known.
    """

    cause: str
    message: str
    time: float | None = None
    configuration: tuple[float, ...] | None = None

    def __str__(self) -> str:
        return self.message

    def to_dict(self) -> dict:
        """JSON-ready form (see :meth:`from_dict`)."""
        return {"cause": self.cause, "message": self.message, "time": self.time,
                "configuration": None if self.configuration is None else list(self.configuration)}

    @classmethod
    def from_dict(cls, data: dict) -> "Failure":
        configuration = data.get("configuration")
        return cls(str(data["cause"]), str(data["message"]), data.get("time"),
                   None if configuration is None else tuple(float(v) for v in configuration))

    @classmethod
    def from_exception(cls, error: Exception, time: float) -> "Failure":
        """The record of ``error`` raised at simulation time ``time`` [s]."""
        message = f"{type(error).__name__} at t = {time:.4f} s: {error}"
        if isinstance(error, PlanningError):
            configuration = None if error.configuration is None else tuple(error.configuration.tolist())
            return cls(error.cause or "planning", message, time, configuration)
        return cls("error", message, time)
