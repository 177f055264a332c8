"""A logged closed-loop run: arrays, metrics, save/load and figures.

All arrays are time-major (one row per logged sample) on a uniform grid ``t`` [s]:
``q_ref``, ``qd_ref``, ``qdd_ref`` (planner reference, rad, rad/s, rad/s^2), ``q_meas``, ``qd_meas``
(plant state), ``tau`` (net joint torque applied by the drives, N m), ``scaling`` (c), ``tcp``
(measured flange pose k(q) = [x, y, z, phi_X, phi_Y, phi_Z], m and rad, base frame) and
``tcp_ref`` (the same of the reference q_ref).

In the figures each joint has its colour, line style and marker (:func:`joint_style`), so joints
stay apart where their lines overlap, and every panel has its legend.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from drake_traj.errors import Cause, DrakeTrajError, Failure, joint_label
from drake_traj.results.exports import export, reference_trajectory
from drake_traj.robots import ROBOT_NAMES, get_robot
from drake_traj.robots.task_space import pose_error
from drake_traj.results.output import OutputError, check_writable
from drake_traj.results.rundir import claim_run_folder
from drake_traj.validation import invalid, path_argument, positive_scalar, real_array

__all__ = ["ARRAY_NAMES", "DEFAULT_TRACKING_TOLERANCE", "LOGGERS", "Metrics", "ResultFileError", "SimulationResult",
           "joint_style"]

SATURATION = 1.0 - 1e-6  # |torque| at or above this fraction of the effort limit counts as saturated
# Far above the shipped scenarios' largest TCP tracking error (0.13 mm, Boryga's SCARA; 0.03 mm on
# the UR10e), far below what an arm asked for the impossible shows (0.3 m at 5x its rated speed).
DEFAULT_TRACKING_TOLERANCE = 0.005  # [m]


class ResultFileError(DrakeTrajError):
    """A saved result cannot be read: names the file and what is wrong with it."""


_JOINT_LINE_STYLES = ("-", "--", "-.")
_JOINT_MARKERS = ("o", "s", "^", "v", "D", "X")


def joint_style(j: int) -> dict:
    """Matplotlib line properties of joint ``j`` (from 0): a colour, a line style and a marker of
    its own (markers spaced along the line, offset per joint), so joints whose lines overlap stay
    apart, not by colour alone."""
    return {"color": f"C{j % 10}", "linestyle": _JOINT_LINE_STYLES[j % len(_JOINT_LINE_STYLES)],
            "marker": _JOINT_MARKERS[j % len(_JOINT_MARKERS)], "markevery": (0.015 * (j % 6), 0.09),
            "markersize": 4.5, "markerfacecolor": "none"}


def _legend(ax) -> None:
    """The panel's own legend, beside it on the right."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def _json_ready(value):
    """``value`` with every non-finite float replaced by None (strict JSON has no NaN)."""
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if isinstance(value, (list, tuple)):
        return [_json_ready(item) for item in value]
    if isinstance(value, dict):
        return {key: _json_ready(item) for key, item in value.items()}
    return value

# The station's loggers (drake_traj.station), by subsystem name: what each records, one column per
# sample (VectorLogSink.data() has one row per entry below, n = the robot's joint count).
LOGGERS = {
    "reference_logger": "the planner's desired_state: q_ref (n rows) then qd_ref (n rows) [rad, rad/s]",
    "acceleration_logger": "the planner's desired_acceleration: qdd_ref (n rows) [rad/s^2]",
    "scaling_logger": "the planner's scaling coefficient c (1 row)",
    "measured_logger": "the plant's state: q_meas (n rows) then qd_meas (n rows) [rad, rad/s]",
    "torque_logger": "the drives' net actuation, PD + feed-forward, saturated (n rows) [N m]",
}

ARRAY_NAMES = ("t", "q_ref", "qd_ref", "qdd_ref", "q_meas", "qd_meas", "tau", "scaling", "tcp", "tcp_ref")
_LIMIT_NAMES = ("velocity_limit", "acceleration_limit", "effort_limit", "waypoints")
# The shape of each array of a result, N samples of n joints (checked by SimulationResult).
_SHAPES = {"t": ("N",), **{name: ("N", "n") for name in ("q_ref", "qd_ref", "qdd_ref", "q_meas", "qd_meas", "tau")},
           "scaling": ("N",), "tcp": ("N", 6), "tcp_ref": ("N", 6), "velocity_limit": ("n",),
           "acceleration_limit": ("n",), "effort_limit": ("n",), "waypoints": (None, 3), "goal": (6,)}


def _over_samples(reduce, array: np.ndarray) -> np.ndarray:
    """``reduce`` (np.min, np.max) of ``array`` over its samples (axis 0); NaN where it holds none
    (a station that has not run)."""
    return reduce(array, axis=0) if len(array) else np.full(array.shape[1:], np.nan)


def _unfinished_failure(samples: int, time: float, finish: float) -> Failure | None:
    """Why a station's log that no failure explains is not a success: ``samples`` logged up to
    the context's ``time`` [s], the planner's ``finish`` [s] (NaN before it finished)."""
    if samples < 2:
        return Failure(Cause.NOT_RUN, f"the station has not run: {samples} sample(s) logged up to t = {time:g} s, less "
                                      "than one log period; advance its simulator (run_station) before from_station", time)
    if not np.isfinite(finish):
        return Failure(Cause.TIMEOUT, f"the planner had not finished when the log ends at t = {time:.4f} s; advance the "
                                      "simulator until it finishes (run_station), or pass the run's failure", time)
    return None


def _output_folder(directory) -> Path:
    """``directory`` (the argument of that name) created if needed, or TypeError/ValueError naming it."""
    directory = path_argument(directory, "directory", "folder")
    try:
        check_writable(directory)
        directory.mkdir(parents=True, exist_ok=True)
    except OutputError as error:
        raise OutputError(f"directory: {error}") from None
    except OSError as error:
        raise OutputError(f"directory: output folder {directory} cannot be created: {error.strerror}") from None
    return directory


@dataclass(frozen=True)
class Metrics:
    """Figures of merit of a run (:meth:`SimulationResult.metrics`); :meth:`to_dict` is the
    content of ``metrics.json``. Joint quantities are per joint, in rad, rad/s, rad/s^2 (m, m/s,
    m/s^2 for prismatic joints); ``*_over_limit`` are ratios to the planner's promised limits (the
    effort limit for torques); ``failure`` is the failure's message and ``failure_cause`` its
    :class:`~drake_traj.errors.Cause` value ("stall", "timeout", ...; both None on success); the final
    errors are those of the measured tool pose at the end of the log against the task's goal (the
    reference's last pose where the task is given in joint space), the orientation error the angle
    of R_goalᵀ R."""

    name: str
    succeeded: bool
    failure: str | None
    failure_cause: str | None
    duration_s: float
    samples: int
    log_period_s: float | None
    qd_min: list[float]
    qd_max: list[float]
    qdd_min: list[float]
    qdd_max: list[float]
    max_velocity_over_limit: float
    max_acceleration_over_limit: float
    max_jerk: float
    tracking_error_joint_max_rad: float
    tracking_error_tcp_max_m: float
    final_position_error_m: float
    final_orientation_error_rad: float
    peak_torque_nm: list[float]
    peak_torque_over_limit: list[float]
    time_at_effort_limit_s: list[float]
    simulated_time_s: float
    wall_time_s: float
    real_time_factor: float | None
    planning_time_s: float | None  # [s] the planner's planning before the run (free motion: find + shorten + time + check)
    unchecked_links: list[str]  # links without collision shapes: the self and cell checks were off for them

    def to_dict(self) -> dict:
        """Strict-JSON-ready dict with the field names as keys (None where a value is not finite)."""
        return _json_ready(asdict(self))


@dataclass
class SimulationResult:
    """One simulated run. ``failure`` is None on success, else why the run stopped early."""

    name: str
    t: np.ndarray
    q_ref: np.ndarray
    qd_ref: np.ndarray
    qdd_ref: np.ndarray
    q_meas: np.ndarray
    qd_meas: np.ndarray
    tau: np.ndarray
    scaling: np.ndarray
    tcp: np.ndarray
    tcp_ref: np.ndarray
    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    effort_limit: np.ndarray
    waypoints: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    goal: np.ndarray = field(default_factory=lambda: np.full(6, np.nan))  # the task-space goal, NaN if none
    duration: float = float("nan")
    failure: Failure | None = None
    wall_time: float = float("nan")
    joint_types: tuple[str, ...] = ()  # "revolute" or "prismatic" per joint; empty: all revolute
    robot: str = ""  # the robot's name (drake_traj.robots.get_robot), where known
    waypoint_neighbourhood: float = float("nan")  # [m] see PlannerSystem.waypoint_neighbourhood(); NaN: none
    planning_time: float = float("nan")  # [s] the planner's own planning (PlannerSystem.planning_time_s); NaN: none
    unchecked_links: tuple[str, ...] = ()  # the robot's links without collision shapes: no self or cell check saw them

    def __post_init__(self):
        """Every array as a float array of its shape (:data:`_SHAPES`), or ValueError naming it.
        Non-finite values are kept (a run that went wrong logs them) and make the run fail
        (:meth:`non_finite_failure`)."""
        sizes = {"N": None, "n": None}
        for name, shape in _SHAPES.items():
            array = real_array(getattr(self, name), name, "see SimulationResult")
            if array.ndim != len(shape):
                raise invalid(name, f"{name} must have {len(shape)} dimension(s) {shape}, got shape {array.shape}")
            for axis, size in zip(shape, array.shape):
                if isinstance(axis, int) and size != axis:
                    raise invalid(name, f"{name} must have shape {shape}, got shape {array.shape}")
                if isinstance(axis, str):
                    if sizes[axis] is None:
                        sizes[axis] = size
                    elif size != sizes[axis]:
                        what = "samples (rows)" if axis == "N" else "joints"
                        raise invalid(name, f"{name} has {size} {what}, t and q_ref {sizes[axis]}: shape {array.shape}")
            setattr(self, name, array)
        if self.failure is not None and not isinstance(self.failure, Failure):
            raise TypeError(f"failure must be a Failure or None, got {type(self.failure).__name__}: {self.failure!r:.80}")

    def joint_unit(self, j: int) -> str:
        """"rad" or "m", the position unit of joint ``j``."""
        return "m" if self.joint_types and self.joint_types[j] == "prismatic" else "rad"

    @property
    def succeeded(self) -> bool:
        """No failure recorded and every logged value finite (:meth:`non_finite_failure`)."""
        return self.failure is None and self.non_finite_failure() is None

    @property
    def joint_names(self) -> tuple[str, ...] | None:
        """The joint names of the robot, where it is one of ours (messages name joints by them);
        None for a robot of one's own, which the registry does not know."""
        return tuple(get_robot(self.robot).joint_names) if self.robot in ROBOT_NAMES else None

    def non_finite_failure(self) -> Failure | None:
        """A :class:`Failure` (cause "non-finite") naming the first logged array and sample that
        holds NaN or an infinity; None when every logged value is finite."""
        for name in ARRAY_NAMES:
            array = getattr(self, name)
            bad = ~np.isfinite(array)
            if bad.any():
                row = int(np.argmax(bad.reshape(len(array), -1).any(axis=1)))
                return Failure(Cause.NON_FINITE, f"the log is not finite: {name}[{row}] = {array[row].tolist()} "
                                             f"at t = {self.t[row]:.4f} s", float(self.t[row]))
        return None

    @property
    def log_period(self) -> float:
        """The logging period [s] (0 with fewer than two samples)."""
        return float(np.median(np.diff(self.t))) if len(self.t) > 1 else 0.0

    def _saturated(self) -> np.ndarray:
        """(N, n) booleans: the joint's torque at its effort limit at that sample."""
        return np.abs(self.tau) >= SATURATION * self.effort_limit

    def execution_failure(self, tracking_tolerance: float) -> Failure | None:
        """Whether the arm did what was planned: a :class:`Failure` when a joint's torque
        saturated at its effort limit (cause "saturation": which joint, from when, for how long)
        or the TCP strayed more than ``tracking_tolerance`` [m] from the reference (cause
        "tracking"), or the log holds NaN or an infinity (:meth:`non_finite_failure`); None
        otherwise."""
        tracking_tolerance = positive_scalar(tracking_tolerance, "tracking_tolerance", "m")
        non_finite = self.non_finite_failure()
        if non_finite is not None:
            return non_finite
        saturated = self._saturated()
        if saturated.any():
            j = int(np.argmax(saturated.any(axis=0)))
            first = int(np.argmax(saturated[:, j]))
            return Failure(Cause.SATURATION, f"{joint_label(j, self.joint_names)}'s torque reached its effort limit "
                                             f"{self.effort_limit[j]:g} at t = {self.t[first]:.3f} s and stayed there "
                                             f"{saturated[:, j].sum() * self.log_period:.3f} s in all: the arm could "
                                             "not follow the reference", float(self.t[first]), tuple(self.q_meas[first]))
        error = self.tcp_position_error()
        if len(error) and not error.max() <= tracking_tolerance:  # NaN is not within the tolerance
            first = int(np.argmax(~(error <= tracking_tolerance)))
            return Failure(Cause.TRACKING, f"the TCP was {1e3 * error.max():.3f} mm from the reference (tolerance "
                                       f"{1e3 * tracking_tolerance:g} mm), first over it at t = {self.t[first]:.3f} s",
                           float(self.t[first]), tuple(self.q_meas[first]))
        return None

    def tcp_position_error(self) -> np.ndarray:
        """Distance [m] between the reference and the measured TCP position at each sample, (N,)."""
        return np.linalg.norm(self.tcp_ref[:, :3] - self.tcp[:, :3], axis=1)

    def jerk(self) -> np.ndarray:
        """Reference jerk [rad/s^3] by finite differences of qdd_ref, shape (N-1, 6)."""
        return np.diff(self.qdd_ref, axis=0) / np.diff(self.t)[:, None]

    def metrics(self) -> Metrics:
        """Scalar and per-joint figures of merit (NaN where the log holds NaN: a NaN is never
        skipped; such a run has not succeeded)."""
        failure = self.failure or self.non_finite_failure()
        tcp_error = self.tcp_position_error()
        simulated = float(self.t[-1]) if len(self.t) else 0.0
        jerk = self.jerk()
        peak_torque = _over_samples(np.max, np.abs(self.tau))
        final_position = final_orientation = float("nan")
        if len(self.t):
            goal = self.goal if np.all(np.isfinite(self.goal)) else self.tcp_ref[-1]
            final_position, final_orientation = pose_error(self.tcp[-1], goal)
        return Metrics(
            name=self.name,
            succeeded=failure is None,
            failure=None if failure is None else failure.message,
            failure_cause=None if failure is None else failure.cause.value,
            duration_s=self.duration,
            samples=int(len(self.t)),
            log_period_s=self.log_period or None,
            qd_min=_over_samples(np.min, self.qd_ref).tolist(),
            qd_max=_over_samples(np.max, self.qd_ref).tolist(),
            qdd_min=_over_samples(np.min, self.qdd_ref).tolist(),
            qdd_max=_over_samples(np.max, self.qdd_ref).tolist(),
            max_velocity_over_limit=float(np.max(_over_samples(np.max, np.abs(self.qd_ref) / self.velocity_limit))),
            max_acceleration_over_limit=float(np.max(_over_samples(np.max, np.abs(self.qdd_ref) / self.acceleration_limit))),
            max_jerk=float(np.abs(jerk).max()) if len(jerk) else 0.0,
            tracking_error_joint_max_rad=float(np.max(_over_samples(np.max, np.abs(self.q_ref - self.q_meas)))),
            tracking_error_tcp_max_m=float(_over_samples(np.max, tcp_error)),
            final_position_error_m=final_position,
            final_orientation_error_rad=final_orientation,
            peak_torque_nm=peak_torque.tolist(),
            peak_torque_over_limit=(peak_torque / self.effort_limit).tolist(),
            time_at_effort_limit_s=(self._saturated().sum(axis=0) * self.log_period).tolist(),
            simulated_time_s=simulated,
            wall_time_s=self.wall_time,
            real_time_factor=simulated / self.wall_time if self.wall_time > 0 else None,
            planning_time_s=self.planning_time if np.isfinite(self.planning_time) else None,
            unchecked_links=list(self.unchecked_links),
        )

    @classmethod
    def from_station(cls, station, station_context, *, name: str = "run", failure: Failure | None = None,
                     wall_time: float = float("nan"), tracking_tolerance: float | None = DEFAULT_TRACKING_TOLERANCE) -> "SimulationResult":
        """The result of a run of a station (:func:`drake_traj.station.build_station`), from its
        loggers, its planner and its robot. ``station_context`` is the station's context (for a
        station inside a larger diagram: ``station.GetMyContextFromRoot(root_context)``).
        The TCP poses are computed from the logged joint positions. A run without ``failure``
        fails all the same where the station has not run (fewer than two samples logged: cause
        NOT_RUN), where the planner had not finished when the log ends (TIMEOUT), or where the
        arm did not do what was planned (:meth:`execution_failure` with ``tracking_tolerance``
        [m]; None skips that check)."""
        if tracking_tolerance is not None:
            positive_scalar(tracking_tolerance, "tracking_tolerance", "m")
        planner = station.GetSubsystemByName("planner")
        robot = station.GetSubsystemByName("tcp_pose").robot
        logs = {}
        for key in LOGGERS:
            logger = station.GetSubsystemByName(key)
            logs[key] = logger.GetLog(station.GetSubsystemContext(logger, station_context))
        count = min(log.num_samples() for log in logs.values())
        data = {key: log.data()[:, :count].T for key, log in logs.items()}
        n = robot.num_joints
        q_ref, q_meas = data["reference_logger"][:, :n], data["measured_logger"][:, :n]
        result = cls(
            name=name,
            t=logs["reference_logger"].sample_times()[:count].copy(),
            q_ref=q_ref,
            qd_ref=data["reference_logger"][:, n:],
            qdd_ref=data["acceleration_logger"],
            q_meas=q_meas,
            qd_meas=data["measured_logger"][:, n:],
            tau=data["torque_logger"],
            scaling=data["scaling_logger"][:, 0],
            tcp=robot.tcp_pose(q_meas).reshape(-1, 6),
            tcp_ref=robot.tcp_pose(q_ref).reshape(-1, 6),
            velocity_limit=np.broadcast_to(planner.velocity_limit, (n,)).astype(float),
            acceleration_limit=np.broadcast_to(planner.acceleration_limit, (n,)).astype(float),
            effort_limit=robot.effort_limits,
            waypoints=planner.task_waypoints(),
            goal=np.full(6, np.nan) if planner.goal_pose() is None else np.asarray(planner.goal_pose(), dtype=float),
            duration=planner.finish_time(station.GetSubsystemContext(planner, station_context)),
            failure=failure,
            wall_time=wall_time,
            joint_types=tuple(robot.joint_types),
            robot=robot.name,
            waypoint_neighbourhood=planner.waypoint_neighbourhood(),
            planning_time=float(getattr(planner, "planning_time_s", float("nan"))),
            unchecked_links=tuple(getattr(planner.guard, "unprotected_links", ())),
        )
        if result.failure is None:
            result.failure = _unfinished_failure(count, station_context.get_time(), result.duration)
        if result.failure is None and tracking_tolerance is not None:
            result.failure = result.execution_failure(tracking_tolerance)
        return result

    # --- persistence ---------------------------------------------------------------------------
    def save(self, directory, *, overwrite: bool = False) -> Path:
        """Write ``result.npz`` (arrays) and ``metrics.json`` into ``directory``; returns it. A folder
        that holds another run is refused (:class:`~drake_traj.rundir.OutputError`) unless
        ``overwrite``, which replaces that run once the new files are complete on disk
        (:mod:`drake_traj.output`); so is a bench's folder or one of other files."""
        directory = path_argument(directory, "directory", "folder")
        with claim_run_folder(directory, overwrite=overwrite, samples=len(self.t), options=("directory", "overwrite=True")) \
                as claimed, claimed.replace() as staging:
            self.write_into(staging)
        return directory

    def write_into(self, staging) -> None:
        """Write ``result.npz`` and ``metrics.json`` into ``staging``, the new content of a claimed
        run folder (:meth:`drake_traj.output.Claim.replace`); :meth:`save` is the way from Python."""
        arrays = {name: getattr(self, name) for name in ARRAY_NAMES + _LIMIT_NAMES + ("goal",)}
        failure = None if self.failure is None else self.failure.to_dict()
        meta = {"name": self.name, "duration": self.duration, "failure": failure, "wall_time": self.wall_time,
                "joint_types": list(self.joint_types), "robot": self.robot,
                "waypoint_neighbourhood": self.waypoint_neighbourhood, "planning_time": self.planning_time,
                "unchecked_links": list(self.unchecked_links)}
        staging.write("result.npz", lambda path: np.savez_compressed(
            path, meta=json.dumps(_json_ready(meta), allow_nan=False), **arrays))
        staging.write("metrics.json", lambda path: path.write_text(
            json.dumps(self.metrics().to_dict(), indent=2, allow_nan=False)))

    @classmethod
    def load(cls, directory) -> "SimulationResult":
        """Read a result written by :meth:`save`; raises :class:`ResultFileError` naming the file
        when it is missing, truncated, corrupted or inconsistent."""
        path = path_argument(directory, "directory", "folder") / "result.npz"
        if not path.is_file():
            raise ResultFileError(f"no result file at {path}")
        names = {f.name for f in fields(cls)}
        try:
            with np.load(path, allow_pickle=False) as data:
                missing = [name for name in ("meta",) + ARRAY_NAMES + _LIMIT_NAMES if name not in data.files]
                if missing:
                    raise ResultFileError(f"{path} is not a complete result: it has no {missing[0]!r}")
                meta = json.loads(str(data["meta"]))
                arrays = {name: np.array(data[name]) for name in ARRAY_NAMES + _LIMIT_NAMES}
                if "goal" in data.files:  # runs saved before the goal was
                    arrays["goal"] = np.array(data["goal"])
        except ResultFileError:
            raise
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
            raise ResultFileError(f"{path} cannot be read (truncated or not a result file): {error}") from None
        if not isinstance(meta, dict) or not {"name", "duration", "failure", "wall_time"} <= set(meta) or set(meta) - names:
            raise ResultFileError(f"{path}: its metadata is not a result's: {meta!r}"[:300])
        samples = len(arrays["t"])
        for name in ARRAY_NAMES:
            if len(arrays[name]) != samples or not np.issubdtype(arrays[name].dtype, np.floating):
                raise ResultFileError(f"{path}: the array {name!r} has {len(arrays[name])} rows of "
                                      f"{arrays[name].dtype}, the log {samples} rows of numbers")
        if arrays["t"].ndim != 1 or not np.all(np.diff(arrays["t"]) > 0):
            raise ResultFileError(f"{path}: the log's times 't' do not increase from sample to sample")
        try:
            if meta["failure"] is not None:
                meta["failure"] = Failure.from_dict(meta["failure"])
            meta["joint_types"] = tuple(meta.get("joint_types", ()))
            meta["unchecked_links"] = tuple(meta.get("unchecked_links", ()))
            for key in ("duration", "wall_time", "waypoint_neighbourhood", "planning_time"):  # NaN is saved as null
                if key in meta:  # (a result saved before the neighbourhood was has none)
                    meta[key] = float("nan") if meta[key] is None else float(meta[key])
        except (KeyError, TypeError, ValueError) as error:
            raise ResultFileError(f"{path}: its metadata is damaged: {error}") from None
        try:
            return cls(**meta, **arrays)
        except (TypeError, ValueError) as error:
            raise ResultFileError(f"{path}: {error}") from None

    def reference_trajectory(self):
        """The reference as a Drake ``PiecewisePolynomial``: the cubic Hermite spline through the
        logged q_ref with the logged q̇_ref as its derivatives (it equals the log at the log times)."""
        return reference_trajectory(self)

    def export(self, path, format: str, **options) -> Path:
        """Write the reference for a robot or another tool (:mod:`drake_traj.export`): ``format``
        "csv", "urscript" or "ros2"; ``options`` as :func:`drake_traj.export.export`."""
        return export(self, path_argument(path, "path"), format, **options)

    # --- figures -------------------------------------------------------------------------------
    def _finish_line(self, axes) -> None:
        """A labelled vertical line at the finish on each of ``axes``."""
        if np.isfinite(self.duration):
            for ax in axes:
                ax.axvline(self.duration, color="black", linewidth=0.8, alpha=0.5,
                           label=f"finished, T = {self.duration:.3f} s")

    def joint_figure(self) -> Figure:
        """q, q̇, q̈ per joint against time, with the velocity and acceleration limit lines."""
        figure = Figure(figsize=(11, 9), layout="constrained")
        axes = figure.subplots(3, 1, sharex=True)
        units = {self.joint_unit(j) for j in range(self.q_ref.shape[1])}
        unit = units.pop() if len(units) == 1 else "rad or m"
        for name, data, limit, ax, suffix in (
            ("q", self.q_ref, None, axes[0], ""),
            ("q̇", self.qd_ref, self.velocity_limit, axes[1], "/s"),
            ("q̈", self.qdd_ref, self.acceleration_limit, axes[2], "/s²"),
        ):
            for j in range(data.shape[1]):
                ax.plot(self.t, data[:, j], label=f"joint {j + 1} [{self.joint_unit(j)}{suffix}]", **joint_style(j))
            if limit is not None and np.all(np.isfinite(limit)):
                for bound in (np.max(limit), -np.max(limit)):
                    ax.axhline(bound, color="grey", linestyle="--", linewidth=1, label="limit" if bound > 0 else None)
            ax.set_ylabel(f"{name} [{unit}{suffix}]")
            ax.grid(True, alpha=0.3)
        self._finish_line(axes)
        axes[-1].set_xlabel("t [s]")
        for ax in axes:
            _legend(ax)
        figure.suptitle(f"{self.name}: joint reference")
        return figure

    def _tcp_error_panel(self, ax) -> None:
        """The TCP position error [mm] (:meth:`tcp_position_error`) against time on ``ax``, its
        largest value in the legend, with the finish line."""
        error = 1e3 * self.tcp_position_error()
        worst = int(np.nanargmax(error)) if len(error) and np.isfinite(error).any() else None
        label = "|p_ref - p_meas|" if worst is None else \
            f"|p_ref - p_meas|, max {error[worst]:.3g} mm at t = {self.t[worst]:.3f} s"
        ax.plot(self.t, error, color="tab:red", label=label)
        self._finish_line([ax])
        ax.set_ylabel("TCP position error [mm]")
        if worst is not None and error[worst] > 0:
            ax.set_ylim(0.0, 1.3 * error[worst])  # room above the curve for the legend
        else:
            ax.set_ylim(bottom=0.0)
        ax.grid(True, alpha=0.3)

    def tracking_figure(self) -> Figure:
        """Joint tracking error q_ref - q_meas, the TCP position error [mm] and the torque over the
        effort limit, against time."""
        figure = Figure(figsize=(11, 8.5), layout="constrained")
        error_ax, tcp_ax, torque_ax = figure.subplots(3, 1, sharex=True)
        for j in range(self.q_ref.shape[1]):
            scale, unit = (1e3, "mm") if self.joint_unit(j) == "m" else (1e3, "mrad")
            error_ax.plot(self.t, scale * (self.q_ref[:, j] - self.q_meas[:, j]), label=f"joint {j + 1} [{unit}]",
                          **joint_style(j))
            torque_ax.plot(self.t, self.tau[:, j] / self.effort_limit[j], label=f"joint {j + 1}", **joint_style(j))
        error_ax.set_ylabel("q_ref - q_meas [mrad or mm]" if self.joint_types and "prismatic" in self.joint_types
                            else "q_ref - q_meas [mrad]")
        self._tcp_error_panel(tcp_ax)
        torque_ax.set_ylabel("effort / effort limit")
        torque_ax.set_xlabel("t [s]")
        self._finish_line([error_ax, torque_ax])
        for ax in (error_ax, tcp_ax, torque_ax):
            ax.grid(True, alpha=0.3)
            _legend(ax)
        figure.suptitle(f"{self.name}: tracking")
        return figure

    def scaling_figure(self) -> Figure:
        """The scaling coefficient c(t); for a planner that does not scale its trajectory (c the
        same throughout), a note saying so on the panel."""
        figure = Figure(figsize=(8, 3), layout="constrained")
        ax = figure.subplots()
        ax.plot(self.t, self.scaling, label="c")
        self._finish_line([ax])
        if len(self.scaling) and np.all(self.scaling == self.scaling[0]):
            ax.text(0.5, 0.5, f"no trajectory scaling: constant {self.scaling[0]:g}", transform=ax.transAxes,
                    ha="center", va="center", fontsize="large", color="dimgrey",
                    bbox={"facecolor": "white", "edgecolor": "lightgrey"})
        ax.set_xlabel("t [s]")
        ax.set_ylabel("c")
        ax.set_ylim(-0.05, 1.05)
        ax.grid(True, alpha=0.3)
        _legend(ax)
        figure.suptitle(f"{self.name}: scaling coefficient")
        return figure

    def tcp_path_figure(self) -> Figure:
        """Left, the measured and reference TCP paths in 3-D (base frame) with the waypoints and,
        for a planner that turns to the next waypoint inside a neighbourhood of each (the Pająk
        planner's ϵ), those neighbourhoods as spheres; right, the distance between the two paths
        [mm] against time, which the 3-D view's scale cannot show."""
        figure = Figure(figsize=(13, 6), layout="constrained")
        grid = figure.add_gridspec(1, 2, width_ratios=(3, 2))
        ax = figure.add_subplot(grid[0], projection="3d")
        ax.plot(*self.tcp_ref[:, :3].T, label="reference", linewidth=2)
        ax.plot(*self.tcp[:, :3].T, "--", label="measured", linewidth=1)
        if len(self.waypoints):
            ax.scatter(*self.waypoints.T, color="tab:orange", s=60, label="waypoints")
        if len(self.waypoints) > 1 and np.isfinite(self.waypoint_neighbourhood):
            self._draw_neighbourhoods(ax)
        if len(self.tcp_ref):
            ax.scatter(*self.tcp_ref[0, :3], color="tab:green", marker="^", s=90, label="start", depthshade=False)
            ax.scatter(*self.tcp_ref[-1, :3], color="black", marker="x", s=60, label="end")
        points = np.vstack([self.tcp_ref[:, :3], self.tcp[:, :3], self.waypoints.reshape(-1, 3)])
        centre = (points.max(axis=0) + points.min(axis=0)) / 2
        half = max(float(np.ptp(points, axis=0).max()) / 2, 1e-3)  # equal scales on all axes
        for set_limits, middle in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            set_limits(middle - half, middle + half)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        # the 3-D panel's legend below it, clear of the box
        figure.legend(*ax.get_legend_handles_labels(), loc="outside lower left", ncols=3, fontsize="small")
        ax.set_title("TCP path (base frame)")
        error_ax = figure.add_subplot(grid[1])
        self._tcp_error_panel(error_ax)
        error_ax.set_xlabel("t [s]")
        error_ax.legend(loc="upper left", fontsize="small")
        error_ax.set_title("the measured TCP off the reference")
        figure.suptitle(f"{self.name}: TCP path")
        return figure

    def _draw_neighbourhoods(self, ax) -> None:
        """Translucent spheres of radius :attr:`waypoint_neighbourhood` around every waypoint
        but the last (where the task ends instead)."""
        radius = self.waypoint_neighbourhood
        azimuth, polar = np.meshgrid(np.linspace(0, 2 * np.pi, 25), np.linspace(0, np.pi, 13))
        unit = np.array([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar), np.cos(polar)])
        for k, centre in enumerate(self.waypoints[:-1]):
            ax.plot_surface(*(centre[:, None, None] + radius * unit), color="tab:orange", alpha=0.15, linewidth=0,
                            label=f"neighbourhood, ϵ = {1e3 * radius:g} mm" if k == 0 else None)

    def figures(self) -> dict[str, Figure]:
        """The run's figures by file stem: joints, tracking, scaling and tcp_path."""
        return {"joints": self.joint_figure(), "tracking": self.tracking_figure(), "scaling": self.scaling_figure(),
                "tcp_path": self.tcp_path_figure()}

    def save_figures(self, directory) -> list[Path]:
        """Write joints.png, tracking.png, scaling.png and tcp_path.png into ``directory``
        (created if needed); returns the paths."""
        directory = _output_folder(directory)
        paths = []
        for stem, figure in self.figures().items():
            path = directory / f"{stem}.png"
            figure.savefig(path, dpi=110)
            paths.append(path)
        return paths
