"""Li et al. 2019's figure: the Cartesian stage's speeds along the path and the executed tool
speed and acceleration against time (matplotlib, imported when a figure is drawn)."""

import numpy as np

from drake_traj.planners.li.repair import tool_speed_and_acceleration

__all__ = ["tool_speed_figure"]


def tool_speed_figure(planner):
    """The break-point limits and look-ahead speeds along the path [mm/s], and the tool speed
    [mm/s] and acceleration [mm/s²] of ``planner`` (a :class:`~.system.LiPathPlanner`) against
    time with its limits, the share of time above 0.5 and 0.8 a_max in the title."""
    from matplotlib.figure import Figure

    cartesian = planner.li_plan.cartesian
    figure = Figure(figsize=(9, 8), layout="constrained")
    path_ax, speed_ax, accel_ax = figure.subplots(3, 1)
    length = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(cartesian.points, axis=0), axis=1))])
    path_ax.plot(1e3 * length, 1e3 * cartesian.limits, label="break-point limit (eq. 4-7)")
    path_ax.plot(1e3 * length, 1e3 * cartesian.velocities, label="after look-ahead (Fig. 2)")
    path_ax.set_xlabel("path length [mm]")
    path_ax.set_ylabel("speed [mm/s]")
    t, speed, acceleration = tool_speed_and_acceleration(planner.law, planner._tool_motion)
    v_max, a_max = planner.tool_limits
    speed_ax.plot(t, 1e3 * speed)
    speed_ax.axhline(1e3 * v_max, color="grey", linestyle="--")
    speed_ax.set_ylabel("tool speed [mm/s]")
    accel_ax.plot(t, 1e3 * acceleration)
    for level, style in ((1.0, "--"), (0.8, ":"), (0.5, ":")):
        accel_ax.axhline(1e3 * level * a_max, color="grey", linestyle=style)
    stats = planner.tool_statistics()
    accel_ax.set_title(
        f"time above 0.5 a_max: {stats['share_above_half_a_max']:.1%}, "
        f"above 0.8 a_max: {stats['share_above_0.8_a_max']:.1%}", fontsize="small")
    accel_ax.set_ylabel("tool |a| [mm/s$^2$]")
    accel_ax.set_xlabel("t [s] (executed motion)")
    for ax in (path_ax, speed_ax, accel_ax):
        ax.grid(True, alpha=0.3)
    path_ax.legend(fontsize="small")
    return figure
