"""A logged closed-loop run: its arrays, its verdict (succeeded, failure: saturation, tracking,
non-finite values) and the station's loggers it is read from; its metrics (:mod:`.metrics`),
files (:mod:`.files`), figures (:mod:`.figures`) and exports (:mod:`.exports`) are one call away.

All arrays are time-major (one row per logged sample) on a uniform grid ``t`` [s]:
``q_ref``, ``qd_ref``, ``qdd_ref`` (planner reference, rad, rad/s, rad/s^2), ``q_meas``, ``qd_meas``
(plant state), ``tau`` (net joint torque applied by the drives, N m), ``scaling`` (c), ``tcp``
(measured flange pose k(q) = [x, y, z, phi_X, phi_Y, phi_Z], m and rad, base frame) and
``tcp_ref`` (the same of the reference q_ref).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from drake_traj.errors import Cause, Failure, joint_label
from drake_traj.results.arrays import ARRAY_NAMES, SHAPES
from drake_traj.results.exports import export, reference_trajectory
from drake_traj.results.figures import (figures_of, joint_figure, save_figures, scaling_figure, tcp_path_figure,
                                        tracking_figure)
from drake_traj.results.files import load_result, save_result, write_result
from drake_traj.results.metrics import Metrics, metrics_of
from drake_traj.robots import ROBOT_NAMES, estimated_torque_note, get_robot
from drake_traj.validation import invalid, path_argument, positive_scalar, real_array

__all__ = ["DEFAULT_TRACKING_TOLERANCE", "LOGGERS", "SimulationResult"]

SATURATION = 1.0 - 1e-6  # |torque| at or above this fraction of the effort limit counts as saturated
# Far above the shipped scenarios' largest TCP tracking error (0.13 mm, Boryga's SCARA; 0.03 mm on
# the UR10e), far below what an arm asked for the impossible shows (0.3 m at 5x its rated speed).
DEFAULT_TRACKING_TOLERANCE = 0.005  # [m]

# The station's loggers (drake_traj.station), by subsystem name: what each records, one column per
# sample (VectorLogSink.data() has one row per entry below, n = the robot's joint count).
LOGGERS = {
    "reference_logger": "the planner's desired_state: q_ref (n rows) then qd_ref (n rows) [rad, rad/s]",
    "acceleration_logger": "the planner's desired_acceleration: qdd_ref (n rows) [rad/s^2]",
    "scaling_logger": "the planner's scaling coefficient c (1 row)",
    "measured_logger": "the plant's state: q_meas (n rows) then qd_meas (n rows) [rad, rad/s]",
    "torque_logger": "the drives' net actuation, PD + feed-forward, saturated (n rows) [N m]",
}


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
    unchecked_collision_pairs: tuple[tuple[str, str, str], ...] = ()  # (link, link, reason): pairs the checks left out
    estimated_inertia: dict = field(default_factory=dict)  # {link: mass [kg]} estimated from its shapes (robot.inertia)
    inertia_density: float = float("nan")  # [kg/m³] of those estimates; NaN: none
    locked_joints: dict = field(default_factory=dict)  # {joint: position [rad or m]} held (robot.locked_joints)

    def __post_init__(self):
        """Every array as a float array of its shape (:data:`SHAPES`), or ValueError naming it.
        Non-finite values are kept (a run that went wrong logs them) and make the run fail
        (:meth:`non_finite_failure`)."""
        sizes = {"N": None, "n": None}
        for name, shape in SHAPES.items():
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

    def saturated(self) -> np.ndarray:
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
        saturated = self.saturated()
        if saturated.any():
            j = int(np.argmax(saturated.any(axis=0)))
            first = int(np.argmax(saturated[:, j]))
            return Failure(Cause.SATURATION, f"{joint_label(j, self.joint_names)}'s torque reached its effort limit "
                                             f"{self.effort_limit[j]:g} at t = {self.t[first]:.3f} s and stayed there "
                                             f"{saturated[:, j].sum() * self.log_period:.3f} s in all: the arm could "
                                             f"not follow the reference{estimated_torque_note(self.estimated_inertia, self.inertia_density)}", float(self.t[first]),
                           tuple(self.q_meas[first]))
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
        skipped; such a run has not succeeded); :func:`~drake_traj.results.metrics.metrics_of`."""
        return metrics_of(self)

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
            unchecked_collision_pairs=tuple(tuple(pair.row()) for pair in getattr(planner.guard, "unchecked_pairs", ())),
            estimated_inertia=dict(getattr(robot, "estimated_inertia", {})),
            inertia_density=float(getattr(robot, "inertia_density", None) or float("nan")),
            locked_joints=dict(getattr(robot, "locked_joints", {})),
        )
        if result.failure is None:
            result.failure = _unfinished_failure(count, station_context.get_time(), result.duration)
        if result.failure is None and tracking_tolerance is not None:
            result.failure = result.execution_failure(tracking_tolerance)
        return result

    # --- files (drake_traj.results.files) ------------------------------------------------------
    def save(self, directory, *, overwrite: bool = False) -> Path:
        """Write ``result.npz`` (arrays) and ``metrics.json`` into ``directory``; returns it. A folder
        that holds another run is refused (:class:`~drake_traj.results.rundir.OutputError`) unless
        ``overwrite``, which replaces that run once the new files are complete on disk
        (:mod:`drake_traj.results.output`); so is a bench's folder or one of other files."""
        return save_result(self, directory, overwrite=overwrite)

    def write_into(self, staging) -> None:
        """Write ``result.npz`` and ``metrics.json`` into ``staging``, the new content of a claimed
        run folder (:meth:`drake_traj.results.output.Claim.replace`); :meth:`save` is the way from Python."""
        write_result(self, staging)

    @classmethod
    def load(cls, directory) -> "SimulationResult":
        """Read a result written by :meth:`save`; raises
        :class:`~drake_traj.results.files.ResultFileError` naming the file when it is missing,
        truncated, corrupted or inconsistent."""
        return load_result(cls, directory)

    def reference_trajectory(self):
        """The reference as a Drake ``PiecewisePolynomial``: the cubic Hermite spline through the
        logged q_ref with the logged q̇_ref as its derivatives (it equals the log at the log times)."""
        return reference_trajectory(self)

    def export(self, path, format: str, **options) -> Path:
        """Write the reference for a robot or another tool (:mod:`drake_traj.results.exports`): ``format``
        "csv", "urscript" or "ros2"; ``options`` as :func:`drake_traj.results.exports.export`."""
        return export(self, path_argument(path, "path"), format, **options)

    # --- figures (drake_traj.results.figures) --------------------------------------------------
    def joint_figure(self) -> Figure:
        """q, q̇, q̈ per joint against time, with the velocity and acceleration limit lines."""
        return joint_figure(self)

    def tracking_figure(self) -> Figure:
        """Joint tracking error q_ref - q_meas, the TCP position error [mm] and the torque over the
        effort limit, against time."""
        return tracking_figure(self)

    def scaling_figure(self) -> Figure:
        """The scaling coefficient c(t); for a planner that does not scale its trajectory (c the
        same throughout), a note saying so on the panel."""
        return scaling_figure(self)

    def tcp_path_figure(self) -> Figure:
        """Left, the measured and reference TCP paths in 3-D (base frame) with the waypoints and
        their neighbourhoods; right, the distance between the two paths [mm] against time."""
        return tcp_path_figure(self)

    def figures(self) -> dict[str, Figure]:
        """The run's figures by file stem: joints, tracking, scaling and tcp_path."""
        return figures_of(self)

    def save_figures(self, directory) -> list[Path]:
        """Write joints.png, tracking.png, scaling.png and tcp_path.png into ``directory``
        (created if needed); returns the paths."""
        return save_figures(self, directory)
