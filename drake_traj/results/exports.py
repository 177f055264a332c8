"""Take a planned motion out of the project: a Drake trajectory, CSV, a URScript program for a
UR e-Series controller, a ROS 2 ``trajectory_msgs/JointTrajectory``. Each file names the robot.

The exported motion is the run's reference (what the planner asked for, not what the simulated
arm did), resampled every ``period`` [s] from t = 0 to the end of the log: q and q̇ from the cubic
Hermite spline through the logged (q_ref, q̇_ref), which passes through every logged sample with
its logged velocity; q̈ linearly interpolated between the logged q̈_ref samples.

Every writer checks its options and the reference first and writes nothing when something is
wrong (:class:`ExportError`, naming the option or the joint, time and value).

Each format is an :class:`ExportFormat` in :data:`FORMATS`, keyed by the name ``--format`` takes:
its file ending, its options' checks and its text. A new format is one class here and its entry.
"""

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from pydrake.trajectories import PiecewisePolynomial

from drake_traj.version import __version__
from drake_traj.errors import DrakeTrajError
from drake_traj.results.output import OutputError, WriteError, check_writable, write_file
from drake_traj.robots import UR_ARMS, Robot, get_robot

__all__ = ["FORMATS", "ExportError", "ExportFormat", "ExportOptions", "export", "reference_trajectory", "resample"]

UR_CYCLE = 0.002  # [s], the UR controller's servo cycle (500 Hz)
MIN_PERIOD = 1e-4  # [s], the finest resampling (10 kHz): the log itself is at 1 ms
LOOKAHEAD_RANGE = (0.03, 0.2)  # [s], servoj lookahead_time (UR script manual)
GAIN_RANGE = (100.0, 2000.0)  # servoj gain (UR script manual)
# The registered arms a UR e-Series controller (PolyScope 5) drives (drake_traj.robots.UR_ARMS); a
# custom arm cannot take one of their names (ChainArm refuses it)
UR_CONTROLLER_ARMS = tuple(arm.name for arm in UR_ARMS)
# Where a ROS 2 JointTrajectory is published: the UR ROS 2 driver's controller for a UR arm
ROS2_TOPICS = {True: "/scaled_joint_trajectory_controller/joint_trajectory",
               False: "/<your_joint_trajectory_controller>/joint_trajectory"}


class ExportError(DrakeTrajError):
    """A reference cannot be exported as asked: names the option, or the joint, time and value."""


def reference_trajectory(result) -> PiecewisePolynomial:
    """The cubic Hermite spline through the logged reference (t, q_ref, q̇_ref) of ``result``."""
    if len(result.t) < 2:
        raise ExportError(f"the run {result.name!r} logged {len(result.t)} sample(s); a trajectory needs two")
    return PiecewisePolynomial.CubicHermite(result.t, result.q_ref.T, result.qd_ref.T)


def resample(result, period: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(t, q, q̇, q̈) every ``period`` [s] from 0 to the end of the log (see the module docstring)."""
    if not np.isfinite(period) or not MIN_PERIOD <= period <= result.t[-1] / 2:
        raise ExportError(f"--period must be between {MIN_PERIOD:g} s and half the logged motion "
                          f"({result.t[-1] / 2:g} s: at least three samples), got {period:g}")
    for name in ("t", "q_ref", "qd_ref", "qdd_ref"):
        bad = np.argwhere(~np.isfinite(getattr(result, name)))
        if len(bad):
            raise ExportError(f"the reference of the run {result.name!r} is not finite: {name} at sample {bad[0][0]} "
                              f"is {getattr(result, name)[tuple(bad[0])]}; nothing was written")
    trajectory = reference_trajectory(result)
    times = np.arange(0, int(np.floor(result.t[-1] / period + 1e-9)) + 1) * period
    derivative = trajectory.MakeDerivative()
    q = np.array([trajectory.value(t).ravel() for t in times])
    qd = np.array([derivative.value(t).ravel() for t in times])
    qdd = np.column_stack([np.interp(times, result.t, column) for column in result.qdd_ref.T])
    return times, q, qd, qdd


def _units(result) -> list[str]:
    return [result.joint_unit(j) for j in range(result.q_ref.shape[1])]


def _csv(result, t, q, qd, qdd, period) -> str:
    n = q.shape[1]
    units = _units(result)
    header = (["t [s]"] + [f"q{j + 1} [{units[j]}]" for j in range(n)] + [f"qd{j + 1} [{units[j]}/s]" for j in range(n)]
              + [f"qdd{j + 1} [{units[j]}/s^2]" for j in range(n)])
    lines = [f"# drake-traj {__version__}: reference of the run {result.name!r} on the {result.robot or 'robot'}, "
             f"every {period:g} s; q and qd from the cubic Hermite spline through the logged (q_ref, qd_ref), "
             "qdd linearly interpolated", ",".join(header)]
    lines += [",".join(f"{value + 0.0:.10g}" for value in row) for row in np.column_stack([t, q, qd, qdd])]  # no -0
    return "\n".join(lines) + "\n"


def ur_model(name: str) -> str:
    """A UR arm's model as UR writes it: ``ur10e`` -> ``UR10e``."""
    return "UR" + name[2:]


def _ur_arm(result) -> Robot:
    """The UR arm of ``result``'s run, or an ExportError naming the arms a UR controller drives."""
    arms = UR_CONTROLLER_ARMS
    if result.robot not in arms:
        models = [ur_model(name) for name in arms]
        served = models[0] if len(models) == 1 else f"{', '.join(models[:-1])} or {models[-1]}"
        raise ExportError(f"URScript runs on a {served} controller; the run {result.name!r} is on "
                          f"{result.robot or 'an unknown robot'}")
    robot = get_robot(result.robot)
    logged = np.asarray(result.effort_limit, dtype=float)
    if logged.shape != robot.effort_limits.shape or not np.allclose(logged, robot.effort_limits, rtol=1e-9, atol=0):
        raise ExportError(f"the run {result.name!r} names the {result.robot}, but its torque limits {logged.tolist()} N m "
                          f"are not the {ur_model(robot.name)}'s {robot.effort_limits.tolist()} N m: it was not run on "
                          f"a {ur_model(robot.name)}, and URScript is not exported for it")
    return robot


def _check_ur_arm(result, t, q, qd) -> Robot:
    """The UR arm of the run (:func:`_ur_arm`), or ExportError for a reference its controller would
    refuse: a joint outside its position range or faster than its rated speed, or a logged torque
    at its torque limit (the simulated drive saturated: the real one would stop the program)."""
    robot = _ur_arm(result)
    model = ur_model(robot.name)
    for values, limit, what, unit, times in ((q, robot.upper_limits, "position", "rad", t),
                                             (qd, robot.velocity_limits, "speed", "rad/s", t),
                                             (result.tau, robot.effort_limits * (1 - 1e-9), "torque", "N m", result.t)):
        over = np.abs(values) > limit
        if over.any():
            k, j = np.argwhere(over)[0]
            raise ExportError(f"joint {j + 1} ({robot.joint_names[j]}) {what} {values[k, j]:.4f} {unit} at t = {times[k]:.3f} s "
                              f"is beyond the {model}'s {limit[j]:.4f} {unit}: the controller would stop the program")
    return robot


def _urscript(result, robot, t, q, period, lookahead_time, gain, approach_speed) -> str:
    program = "drake_traj_" + "".join(c if c.isalnum() else "_" for c in result.name)
    lines = [
        f"def {program}():",
        f"  # drake-traj {__version__}: the reference of the run {result.name!r} for a {ur_model(robot.name)}, "
        f"{len(t)} points every {period:g} s",
        "  # (q from the cubic Hermite spline through the logged reference). Try it at reduced speed first.",
        f"  movej({_ur_list(q[0])}, a={approach_speed:g}, v={approach_speed:g})  # to the start, slowly",
    ]
    lines += [f"  servoj({_ur_list(row)}, t={period:g}, lookahead_time={lookahead_time:g}, gain={gain:g})" for row in q]
    lines += ["  stopj(2.0)", "end", f"{program}()"]
    return "\n".join(lines) + "\n"


def _ur_list(values) -> str:
    return "[" + ", ".join(f"{value:.8f}" for value in values) + "]"


def _ros2(result, t, q, qd, qdd, joint_names) -> str:
    points = []
    for time, position, velocity, acceleration in zip(t, q, qd, qdd):
        sec = int(np.floor(time + 1e-12))
        nanosec = int(round((time - sec) * 1e9))
        if nanosec >= 1_000_000_000:
            sec, nanosec = sec + 1, nanosec - 1_000_000_000
        points.append({"positions": position.tolist(), "velocities": velocity.tolist(),
                       "accelerations": acceleration.tolist(), "effort": [],
                       "time_from_start": {"sec": sec, "nanosec": nanosec}})
    message = {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "joint_names": list(joint_names),
               "points": points}
    comment = (f"# trajectory_msgs/JointTrajectory from drake-traj {__version__}: the reference of the run {result.name!r} "
               f"on the {result.robot or 'robot'}\n"
               f"# (ros2 topic pub --once {ROS2_TOPICS[result.robot in UR_CONTROLLER_ARMS]} "
               "trajectory_msgs/msg/JointTrajectory \"$(cat FILE)\")\n")
    return comment + yaml.safe_dump(message, sort_keys=False, default_flow_style=None, width=1000)


@dataclass(frozen=True)
class ExportOptions:
    """The options of an export (``drake-traj export``'s): the sampling ``period`` [s], and for
    URScript servoj's ``lookahead_time`` [s] and ``gain`` and the ``approach_speed`` [rad/s, rad/s²]."""

    period: float = UR_CYCLE
    lookahead_time: float = 0.1
    gain: float = 300.0
    approach_speed: float = 0.3


class ExportFormat:
    """One export format: its file ending (``suffix``), the check of its own options (before any
    work) and its text from the resampled reference."""

    suffix: str = ""

    def check_options(self, options: ExportOptions) -> None:
        """Raise :class:`ExportError` for an option this format cannot take; the base takes any."""

    def text(self, result, t, q, qd, qdd, options: ExportOptions) -> str:
        """The file's text for ``result``'s reference resampled at the times ``t`` [s]: q, q̇, q̈
        (len(t), n) [rad or m, per s, per s²]; raises :class:`ExportError` where the reference does
        not fit the format."""
        raise NotImplementedError(f"{type(self).__name__} does not say how to write its text")


class CsvFormat(ExportFormat):
    """Comma-separated values: t, q, q̇, q̈ per row, with a header naming the units."""

    suffix = ".csv"

    def text(self, result, t, q, qd, qdd, options):
        return _csv(result, t, q, qd, qdd, options.period)


class UrscriptFormat(ExportFormat):
    """A URScript program for a UR e-Series controller: a slow movej to the start, then servoj
    every ``period``; for the UR arms only, within their ranges, speeds and torques."""

    suffix = ".script"

    def check_options(self, options):
        if not options.period >= UR_CYCLE - 1e-12:
            raise ExportError(f"--period must be at least the UR controller's cycle {UR_CYCLE} s, got {options.period}")
        for name, value, (low, high) in (("--lookahead-time", options.lookahead_time, LOOKAHEAD_RANGE),
                                         ("--gain", options.gain, GAIN_RANGE)):
            if not low <= value <= high:
                raise ExportError(f"{name} must be in UR's range [{low:g}, {high:g}], got {value}")
        if not 0 < options.approach_speed <= 1.0:
            raise ExportError(f"--approach-speed must be in (0, 1] rad/s, got {options.approach_speed}")

    def text(self, result, t, q, qd, qdd, options):
        robot = _check_ur_arm(result, t, q, qd)
        return _urscript(result, robot, t, q, options.period, options.lookahead_time, options.gain,
                         options.approach_speed)


class Ros2Format(ExportFormat):
    """A ROS 2 ``trajectory_msgs/JointTrajectory`` message as YAML (``ros2 topic pub``)."""

    suffix = ".yaml"

    def text(self, result, t, q, qd, qdd, options):
        return _ros2(result, t, q, qd, qdd, result.joint_names or [f"joint_{j + 1}" for j in range(q.shape[1])])


FORMATS: dict[str, ExportFormat] = {"csv": CsvFormat(), "urscript": UrscriptFormat(), "ros2": Ros2Format()}
"""Each export format by the name ``--format`` takes."""


def export(result, path, format: str, *, period: float = UR_CYCLE, lookahead_time: float = 0.1, gain: float = 300.0,
           approach_speed: float = 0.3, allow_failed: bool = False, run_folder=None) -> Path:
    """Write ``result``'s reference to ``path`` as ``format``, a name of :data:`FORMATS` ("csv",
    "urscript" or "ros2").

    A run that failed (its planner did not finish, or the arm could not follow) is refused unless
    ``allow_failed``; then the file says so in its header.

    Args:
        period: the sampling period [s] (URScript: at least the controller's 2 ms cycle).
        lookahead_time: servoj's lookahead time [s], in UR's range 0.03-0.2 (URScript only).
        gain: servoj's gain, in UR's range 100-2000 (URScript only).
        approach_speed: the movej to the start configuration, [rad/s] and [rad/s²] (URScript only).
        run_folder: the exported run's folder, the one run folder ``path`` may be in (its lock held
            by the caller, as ``drake-traj export`` does); None: no run's or bench's folder.

    Returns the path written. Raises :class:`ExportError`, writing nothing, when an option is out
    of range or the reference is not fit for the format; :class:`~drake_traj.results.output.OutputError`
    when ``path`` is a symbolic link or in another run's or bench's folder, its folder cannot be
    written (a read-only file system, no permission: checked first, naming the folder), or it
    does not fit on the disk (:func:`drake_traj.results.output.write_file`: the file is written whole or
    not at all).
    """
    if format not in FORMATS:
        raise ExportError(f"--format must be one of {sorted(FORMATS)}, got {format!r}")
    if result.failure is not None and not allow_failed:
        raise ExportError(f"the run {result.name!r} failed ({result.failure}); its reference is not a motion to "
                          "send anywhere. Nothing was written (--allow-failed writes it anyway, marked as failed)")
    options = ExportOptions(period, lookahead_time, gain, approach_speed)
    FORMATS[format].check_options(options)
    folder = Path(os.path.abspath(path)).parent
    if folder.is_dir():  # a missing folder is named by write_file
        try:
            check_writable(folder)  # e.g. a read-only file system: before the work
        except OutputError as error:
            raise error.relocated(error.field, f"--out {path}: {error}; nothing was written") from None
    t, q, qd, qdd = resample(result, period)
    text = FORMATS[format].text(result, t, q, qd, qdd, options)
    if result.failure is not None:  # allowed: the first line says so (a comment in all three formats)
        text = f"# FAILED RUN: {' '.join(str(result.failure).split())}\n" + text
    try:
        return write_file(path, text, own_folder=run_folder)
    except OutputError:
        raise
    except OSError as error:  # the folder changed since it was checked
        raise WriteError(f"--out {path}: the folder {folder} cannot be written: {error.strerror or error}; nothing was "
                         "written") from None
