"""Li et al. 2019 under the planner contract: the closed test path of Fig. 6, the config, ``make``
and :class:`LiPathPlanner` (the joint spline of :func:`~.plan.plan_li_path` on the scaled clock)."""

import math
from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.base import TimeLawPlanner
from drake_traj.planners.li.plan import LiPlan, plan_li_path
from drake_traj.planners.li.repair import tool_speed_and_acceleration
from drake_traj.robots import LI_4DOF, Robot
from drake_traj.validation import instance_of, limit_or_default, real_array

__all__ = ["CARTESIAN_ACCELERATION_LIMIT", "CARTESIAN_VELOCITY_LIMIT", "LiConfig", "LiPathPlanner", "li_closed_path",
           "make"]

# Table 4: Sup |V_m| = 200 mm/s, Sup |a_m| = 100 mm/s^2 (the tool limits of the paper's experiment).
CARTESIAN_VELOCITY_LIMIT = 0.2  # [m/s]
CARTESIAN_ACCELERATION_LIMIT = 0.1  # [m/s^2]

# ------------------------------------------------------------------------------------------------
# The closed test path of Fig. 6.
# ------------------------------------------------------------------------------------------------

# Segments in mm, in the plane Z = 0, anticlockwise from S = (200, -74):
#   ("line", end) or ("arc", center, radius, start angle, end angle) [deg; end < start: clockwise].
_PATH_START = (200.0, -74.0)
_PATH_SEGMENTS = (
    ("line", (360.0, -74.0)),  # S -> bottom right: a long straight start, as S -> P_b in Fig. 6
    ("arc", (360.0, -34.0), 40.0, -90.0, 0.0),  # R 40 quarter
    ("line", (400.0, 30.0)),
    ("arc", (380.0, 30.0), 20.0, 0.0, 90.0),  # R 20 quarter
    ("line", (300.0, 50.0)),
    ("line", (300.0, 20.0)),  # 90-degree corner, short line into the notch
    ("arc", (285.0, 20.0), 15.0, 0.0, -180.0),  # R 15 half circle, clockwise (concave notch)
    ("line", (270.0, 50.0)),
    ("line", (230.0, 50.0)),  # 90-degree corner
    ("arc", (230.0, 20.0), 30.0, 90.0, 180.0),  # R 30 quarter
    ("line", _PATH_START),  # back down to S (90-degree corner at S)
)


def li_closed_path(points_per_mm: float = 1.0) -> np.ndarray:
    """A closed path like the paper's Fig. 6, in the XY plane at Z = 0, in the robot's base [m].

    Straight lines, quarter arcs of radii 40, 20 and 30 mm, a clockwise half circle of 15 mm (a
    notch) and three 90-degree corners; 686.5 mm long, anticlockwise (seen from +Z) from
    S = (0.200, -0.074, 0). Every segment is sampled at equal steps of about 1 / points_per_mm mm
    with its end points (break points and arc ends) included exactly. The last row repeats S, so
    the path is closed; at the default density there are 686 distinct points (the paper's count),
    687 rows.

    Placement (the paper's Fig. 6 is not readable beyond its X axis 150-350 mm): x in
    [200, 400] mm, y in [-74, 50] mm, i.e. the figure's 200 mm width moved +50 mm in X. With the
    pen (last link) vertical, q3 >= -0.25 pi keeps the point at least 156.4 mm from the joint-1
    axis, so X = 150 mm near Y = 0 is out of reach; here the path is 200-402 mm from the axis:
    q3 keeps >= 0.15 rad from its lower limit, the elbow is never stretched (arccos argument
    <= 0.36), |q1| <= 0.36 rad, and the tool speed of 200 mm/s needs |qd1| <= 1 rad/s.

    Args:
        points_per_mm: sampling density along the path [1/mm], > 0.

    Returns:
        (N, 3) positions [m].
    """
    density = float(points_per_mm)
    if not math.isfinite(density) or density <= 0.0:
        raise ValueError(f"points_per_mm must be positive and finite, got {points_per_mm!r}")
    pieces = []
    start = np.array(_PATH_START)
    for segment in _PATH_SEGMENTS:
        if segment[0] == "line":
            end = np.array(segment[1])
            length = float(np.linalg.norm(end - start))
            n = max(1, int(round(length * density)))
            pieces.append(start + np.linspace(0.0, 1.0, n + 1)[:-1, None] * (end - start))
        else:
            _, center, radius, a0, a1 = segment
            a0, a1 = math.radians(a0), math.radians(a1)
            n = max(1, int(round(abs(a1 - a0) * radius * density)))
            theta = np.linspace(a0, a1, n + 1)[:-1]
            arc = np.stack([center[0] + radius * np.cos(theta), center[1] + radius * np.sin(theta)], 1)
            arc[0] = start  # exactly the previous segment's end
            pieces.append(arc)
            end = np.array([center[0] + radius * math.cos(a1), center[1] + radius * math.sin(a1)])
            end = np.round(end, 9)  # cos(90 deg) etc.: the end is a grid point
        start = end
    pieces.append(np.array([_PATH_START]))
    xy = np.concatenate(pieces) / 1000.0
    return np.column_stack([xy, np.zeros(len(xy))])


class LiPathPlanner(TimeLawPlanner):
    """Li et al. 2019's planner under the contract: follows :attr:`LiPlan.law` on the scaled clock.

    Args:
        plan: from :func:`plan_li_path`.
        velocity_limit, acceleration_limit: the joint limits the plan keeps.
        tool_motion: the robot's FK rates, for the tool speed figure.
        tool_limits: (speed [m/s], acceleration [m/s^2]) of the tool.
    """

    def __init__(self, plan: LiPlan, velocity_limit, acceleration_limit, tool_motion, tool_limits):
        instance_of(plan, LiPlan, "plan")
        super().__init__(plan.law, velocity_limit, acceleration_limit)
        self.li_plan = plan
        self._tool_motion = tool_motion
        self.tool_limits = tool_limits

    def tool_statistics(self) -> dict:
        """Tool speed and acceleration peaks and the share of time above 0.5 and 0.8 a_max
        (the paper's efficiency figure), on dense samples."""
        t, speed, acceleration = tool_speed_and_acceleration(self.law, self._tool_motion)
        v_max, a_max = self.tool_limits
        weights = np.gradient(t)
        return {
            "peak_speed": float(speed.max()),
            "peak_acceleration": float(acceleration.max()),
            "share_above_half_a_max": float(weights[acceleration > 0.5 * a_max].sum() / t[-1]),
            "share_above_0.8_a_max": float(weights[acceleration > 0.8 * a_max].sum() / t[-1]),
        }

    def figures(self) -> dict:
        from matplotlib.figure import Figure

        cartesian = self.li_plan.cartesian
        figure = Figure(figsize=(9, 8), layout="constrained")
        path_ax, speed_ax, accel_ax = figure.subplots(3, 1)
        length = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(cartesian.points, axis=0), axis=1))])
        path_ax.plot(1e3 * length, 1e3 * cartesian.limits, label="break-point limit (eq. 4-7)")
        path_ax.plot(1e3 * length, 1e3 * cartesian.velocities, label="after look-ahead (Fig. 2)")
        path_ax.set_xlabel("path length [mm]")
        path_ax.set_ylabel("speed [mm/s]")
        t, speed, acceleration = tool_speed_and_acceleration(self.law, self._tool_motion)
        v_max, a_max = self.tool_limits
        speed_ax.plot(t, 1e3 * speed)
        speed_ax.axhline(1e3 * v_max, color="grey", linestyle="--")
        speed_ax.set_ylabel("tool speed [mm/s]")
        accel_ax.plot(t, 1e3 * acceleration)
        for level, style in ((1.0, "--"), (0.8, ":"), (0.5, ":")):
            accel_ax.axhline(1e3 * level * a_max, color="grey", linestyle=style)
        stats = self.tool_statistics()
        accel_ax.set_title(
            f"time above 0.5 a_max: {stats['share_above_half_a_max']:.1%}, "
            f"above 0.8 a_max: {stats['share_above_0.8_a_max']:.1%}", fontsize="small")
        accel_ax.set_ylabel("tool |a| [mm/s$^2$]")
        accel_ax.set_xlabel("t [s] (executed motion)")
        for ax in (path_ax, speed_ax, accel_ax):
            ax.grid(True, alpha=0.3)
        path_ax.legend(fontsize="small")
        return {"tool_speed": figure}


@dataclass
class LiConfig:
    """Li et al. 2019: look-ahead and cubic ACC/DEC on a tool path, IK, joint re-timing, quintic
    B-spline, and our repairs so every limit holds: the scenario's ``planner: !LiConfig`` entry.

    Attributes:
        points: the tool path [m] in the robot's base frame, one row of 3 per point; empty: the
            closed path like Fig. 6 (:func:`li_closed_path`), for robots other than the paper's
            4-DOF robot translated so that it starts at the tool at ``q_initial`` (the tool keeps
            that orientation where it has one).
        tool_velocity_limit, tool_acceleration_limit: Table 4's tool limits [m/s, m/s^2].
        velocity_limit, acceleration_limit: per joint; empty: the robot's joint-move limits
            (Table 5 for the 4-DOF robot; 1.05 rad/s, 1.40 rad/s^2 for the UR10e).
    """

    points: list[list[float]] = field(default_factory=list)
    tool_velocity_limit: float = CARTESIAN_VELOCITY_LIMIT
    tool_acceleration_limit: float = CARTESIAN_ACCELERATION_LIMIT
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)


def make(config: LiConfig, robot: Robot, q_initial) -> LiPathPlanner:
    """The planner of ``config`` on ``robot`` (``q_initial``: see :class:`LiConfig`)."""
    q_initial = np.asarray(q_initial, dtype=float)
    if np.size(config.points):
        points = real_array(config.points, "points", "m")
        if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
            raise ValueError(f"points must be a list of at least two [x, y, z] rows [m], got shape {points.shape}")
        for index, point in enumerate(points):  # named by its index before the path between them is solved
            try:
                robot.point_ik(point[None], q_initial)
            except ValueError as error:
                raise ValueError(f"points[{index}]: {error}") from error
    else:
        points = li_closed_path()
        if robot.name != LI_4DOF.name:
            points = points - points[0] + robot.tool_position(q_initial)
    default_velocity, default_acceleration = robot.joint_move_limits
    n = robot.num_joints
    velocity = limit_or_default(config.velocity_limit, default_velocity, "velocity_limit", n)
    acceleration = limit_or_default(config.acceleration_limit, default_acceleration, "acceleration_limit", n)
    tool_limits = (config.tool_velocity_limit, config.tool_acceleration_limit)
    plan = plan_li_path(points, lambda path: robot.point_ik(path, q_initial), robot.tool_motion, velocity,
                        acceleration, *tool_limits)
    return LiPathPlanner(plan, velocity, acceleration, robot.tool_motion, tool_limits)
