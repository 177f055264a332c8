"""The package's exceptions, their causes and locations as data, and the record of a failed run.

Every error drake_traj raises on purpose derives from :class:`DrakeTrajError`, itself a
``ValueError``: bad input (a malformed argument, an unreachable pose, infeasible limits) and a
task the planner cannot complete alike. Each carries

- ``field``: where the input that caused it is, as a path of names and indices, e.g.
  ``("planner", "waypoints", 3)`` (empty where no one input is to blame);
- ``cause``: a :class:`Cause`, what went wrong.

The command line and the scenario reader locate an error in a YAML file from ``field``, and decide
what to do from ``cause``: no message text is ever parsed. A simulation that stops early keeps
what it logged and describes why in a :class:`Failure`, whose ``cause`` is a :class:`Cause` too.
"""

from __future__ import annotations

import difflib
import enum
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Cause", "DrakeTrajError", "Failure", "Field", "PlanningError", "SingularConfigurationError", "UnreachablePoseError",
    "did_you_mean", "field_text", "in_chain", "interrupt_in", "joint_label", "reraise_interrupt",
]

Field = tuple  # tuple[str | int, ...]: field names and list indices, outermost first


class Cause(str, enum.Enum):
    """Why an input was refused or a run stopped. A ``str`` (``Cause.STALL == "stall"``):
    ``metrics.json`` and ``run.json`` write its value."""

    INVALID = "invalid"  # a malformed argument or field: type, shape, range, unknown name
    UNREACHABLE = "unreachable"  # a pose outside the robot's reach, or an IK branch that does not exist
    SINGULAR = "singular"  # a singular configuration, or the law stalled at one
    INFEASIBLE = "infeasible"  # limits or geometry the task cannot meet
    STALL = "stall"  # the online law stopped making progress
    PLANNING = "planning"  # the planner could not complete the task for another reason
    NON_FINITE = "non-finite"  # NaN or an infinity in the law or the log
    TIMEOUT = "timeout"  # not finished within the run's or the preflight's time
    NOT_RUN = "not run"  # a result of a station that has not run (less than one log period logged)
    INTERRUPTED = "interrupted"  # Ctrl-C or SIGTERM
    SATURATION = "saturation"  # a joint's torque reached its effort limit
    TRACKING = "tracking"  # the arm strayed further than the tolerance from the reference
    COLLISION = "collision"  # the arm touches (or would come closer than the clearance to) itself, its tool or its cell
    JOINT_RANGE = "joint range"  # a joint past its position range
    OUTPUT = "output"  # an output folder or file that cannot be written
    ERROR = "error"  # any other exception during a run

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


def field_text(field: Field) -> str:
    """The field path as it is written in a scenario file: ``("planner", "waypoints", 3)`` ->
    ``planner.waypoints[3]``."""
    text = ""
    for part in field:
        text += f"[{part}]" if isinstance(part, int) else f"{'.' if text else ''}{part}"
    return text


def joint_label(j: int, names=None) -> str:
    """Joint ``j`` (0-based index) as every message names it: ``joint 2 (shoulder_lift_joint)``,
    1-based, with its name where known."""
    return f"joint {j + 1}" + (f" ({names[j]})" if names is not None else "")


def did_you_mean(word, known, *, tags: bool = False) -> str:
    """"did you mean 'goals'?" naming the entries of ``known`` closest to ``word`` (a misspelt
    field, scenario, variant or robot): up to three of :func:`difflib.get_close_matches`, those
    nearly as close as the closest, quoted, or written as YAML tags with ``tags`` ("did you mean
    !PajakConfig?"); "" when none is close."""
    if not isinstance(word, str):
        return ""
    ratios = {item: difflib.SequenceMatcher(None, word, item).ratio() for item in map(str, known)}
    best = max(ratios.values(), default=0.0)
    close = [f"!{item}" if tags else repr(item) for item in difflib.get_close_matches(word, ratios, n=3)
             if ratios[item] >= best - 0.1]
    if not close:
        return ""
    return f"did you mean {close[0] if len(close) == 1 else ', '.join(close[:-1]) + ' or ' + close[-1]}?"


def in_chain(error: BaseException | None, kind: type):
    """The first exception of type ``kind`` among ``error`` and the errors behind it (each one's
    ``__cause__``, else its ``__context__``, even one ``raise ... from None`` hides: a
    :meth:`DrakeTrajError.relocated` copy raised so has the error it copies there), or None."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, kind):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def interrupt_in(error: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt (Ctrl-C, or SIGTERM as the command line raises it) that is ``error``
    or lies behind it (:func:`in_chain`), else None. A signal handled as compiled code returns to
    Python (numba's dispatcher) surfaces as a SystemError ("returned a result with an exception
    set") whose cause is the KeyboardInterrupt: whatever catches ``Exception`` to keep a failure
    as a result re-raises this instead, so that the stop stops."""
    return in_chain(error, KeyboardInterrupt)


def reraise_interrupt(error: BaseException) -> None:
    """Raise the KeyboardInterrupt behind ``error`` (:func:`interrupt_in`), if there is one: the
    first line of an ``except Exception`` that turns a failure into a result."""
    stop = interrupt_in(error)
    if stop is not None:
        raise stop from None


def _restore(cls, message: str, state: dict):
    """Unpickle a :class:`DrakeTrajError` (its attributes travel with it, e.g. from a Dask worker)."""
    error = cls.__new__(cls)
    Exception.__init__(error, message)
    error.__dict__.update(state)
    return error


class DrakeTrajError(ValueError):
    """Base of every error raised by drake_traj on purpose.

    Args:
        message: what is wrong, naming the input and the reason.
        field: where the input is (:data:`Field`), e.g. ``("waypoints", 3)``; a caller that knows
            the enclosing field re-raises it there (:meth:`relocated`).
        cause: what went wrong; default the class's ``default_cause``.
    """

    default_cause = Cause.INVALID

    def __init__(self, message: str, *, field: Field = (), cause: Cause | None = None):
        super().__init__(message)
        self.field = tuple(field)
        self.cause = Cause(cause) if cause is not None else self.default_cause

    def __reduce__(self):
        return _restore, (type(self), str(self), dict(self.__dict__))

    def relocated(self, field: Field, message: str) -> "DrakeTrajError":
        """A copy of this error (same type, cause and other attributes) at ``field`` with the text
        ``message``: how a caller that knows the enclosing field (a scenario's ``planner``)
        passes the error on."""
        error = _restore(type(self), message, dict(self.__dict__))
        error.field = tuple(field)
        return error


class SingularConfigurationError(DrakeTrajError):
    """A kinematic quantity is undefined at this configuration or pose (a singular Jacobian,
    Euler-angle gimbal lock, an IK branch that does not exist there)."""

    default_cause = Cause.SINGULAR


class UnreachablePoseError(DrakeTrajError):
    """A pose no joint solution within the joint ranges takes (any IK branch): the arm's reach, its
    shoulder offset or its joint ranges rule it out.

    Attributes:
        pose: X_BF (4, 4), the flange pose asked for, in the arm's base frame [m]: what an
            independent check of the refusal solves for (the soak's, with Drake's InverseKinematics).
    """

    default_cause = Cause.UNREACHABLE

    def __init__(self, message: str, *, pose, field: Field = ()):
        super().__init__(message, field=field)
        self.pose = np.array(pose, dtype=float)


class PlanningError(DrakeTrajError):
    """The planner cannot complete the task: names the time, configuration and cause.

    Attributes:
        time: simulation time [s] (None if not known).
        configuration: q [rad] at that time (None if not known).
        cause: a :class:`Cause` (STALL, SINGULAR, NON_FINITE, TIMEOUT, UNREACHABLE, ...).
        field: the input to blame where there is one, e.g. ``("waypoints", 2)``.
        partial: what was computed before the failure (dict of arrays), where a caller keeps it.
    """

    default_cause = Cause.PLANNING

    def __init__(self, message: str, *, time=None, configuration=None, cause: Cause | None = None,
                 field: Field = (), partial=None):
        where = ""
        if time is not None:
            where = f"at t = {float(time):.4f} s"
        if configuration is not None:
            where += f"{', ' if where else 'at '}q = {np.round(np.asarray(configuration, float), 4).tolist()}"
        super().__init__(f"{message} ({where})" if where else message, field=field, cause=cause)
        self.time = time
        self.configuration = None if configuration is None else np.array(configuration, dtype=float)
        self.partial = partial


@dataclass(frozen=True)
class Failure:
    """Why a simulated run stopped before its planner finished.

    Attributes:
        cause: a :class:`Cause`: a :class:`PlanningError`'s (STALL, SINGULAR, ...), TIMEOUT
            (``max_duration`` reached, or a log that ends before the planner finished), NOT_RUN
            (a station that has not run), INTERRUPTED, SATURATION, TRACKING, NON_FINITE, or ERROR
            (any other exception).
        message: the human-readable reason (for an exception: its type, time and text).
        time: simulation time of the failure [s], if known.
        configuration: the reference q at that time [rad], if known.
    """

    cause: Cause
    message: str
    time: float | None = None
    configuration: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "cause", Cause(self.cause))  # a value read back from a file, too

    def __str__(self) -> str:
        return self.message

    def to_dict(self) -> dict:
        """JSON-ready form (see :meth:`from_dict`)."""
        return {"cause": self.cause.value, "message": self.message, "time": self.time,
                "configuration": None if self.configuration is None else list(self.configuration)}

    @classmethod
    def from_dict(cls, data: dict) -> "Failure":
        configuration = data.get("configuration")
        return cls(Cause(data["cause"]), str(data["message"]), data.get("time"),
                   None if configuration is None else tuple(float(v) for v in configuration))

    @classmethod
    def from_exception(cls, error: Exception, time: float) -> "Failure":
        """The record of ``error`` raised at simulation time ``time`` [s]: its type, the time
        (unless a :class:`PlanningError`'s text already gives that time) and its text."""
        said = isinstance(error, PlanningError) and error.time is not None and f"{float(error.time):.4f}" == f"{time:.4f}"
        message = f"{type(error).__name__}: {error}" if said else f"{type(error).__name__} at t = {time:.4f} s: {error}"
        if isinstance(error, PlanningError):
            configuration = None if error.configuration is None else tuple(error.configuration.tolist())
            return cls(error.cause, message, time, configuration)
        return cls(Cause.ERROR, message, time)
