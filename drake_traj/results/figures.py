"""A run's matplotlib figures, of a :class:`~drake_traj.results.result.SimulationResult`: the joint
reference, the tracking, the scaling coefficient and the TCP path (base frame), each against time
t [s] where it has a time axis.

Each joint has its colour, line style and marker (:func:`joint_style`), so joints stay apart where
their lines overlap, and every panel has its legend.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from drake_traj.results.files import output_folder

__all__ = ["figures_of", "joint_figure", "joint_style", "save_figures", "scaling_figure", "tcp_path_figure",
           "tracking_figure"]

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


def _finish_line(result, axes) -> None:
    """A labelled vertical line at the finish of ``result`` (its duration [s]) on each of ``axes``."""
    if np.isfinite(result.duration):
        for ax in axes:
            ax.axvline(result.duration, color="black", linewidth=0.8, alpha=0.5,
                       label=f"finished, T = {result.duration:.3f} s")


def joint_figure(result) -> Figure:
    """q, q̇, q̈ per joint against time, with the velocity and acceleration limit lines."""
    figure = Figure(figsize=(11, 9), layout="constrained")
    axes = figure.subplots(3, 1, sharex=True)
    units = {result.joint_unit(j) for j in range(result.q_ref.shape[1])}
    unit = units.pop() if len(units) == 1 else "rad or m"
    for name, data, limit, ax, suffix in (
        ("q", result.q_ref, None, axes[0], ""),
        ("q̇", result.qd_ref, result.velocity_limit, axes[1], "/s"),
        ("q̈", result.qdd_ref, result.acceleration_limit, axes[2], "/s²"),
    ):
        for j in range(data.shape[1]):
            ax.plot(result.t, data[:, j], label=f"joint {j + 1} [{result.joint_unit(j)}{suffix}]", **joint_style(j))
        if limit is not None and np.all(np.isfinite(limit)):
            for bound in (np.max(limit), -np.max(limit)):
                ax.axhline(bound, color="grey", linestyle="--", linewidth=1, label="limit" if bound > 0 else None)
        ax.set_ylabel(f"{name} [{unit}{suffix}]")
        ax.grid(True, alpha=0.3)
    _finish_line(result, axes)
    axes[-1].set_xlabel("t [s]")
    for ax in axes:
        _legend(ax)
    figure.suptitle(f"{result.name}: joint reference")
    return figure


def _tcp_error_panel(result, ax) -> None:
    """The TCP position error [mm] (``result.tcp_position_error()``) against time on ``ax``, its
    largest value in the legend, with the finish line."""
    error = 1e3 * result.tcp_position_error()
    worst = int(np.nanargmax(error)) if len(error) and np.isfinite(error).any() else None
    label = "|p_ref - p_meas|" if worst is None else \
        f"|p_ref - p_meas|, max {error[worst]:.3g} mm at t = {result.t[worst]:.3f} s"
    ax.plot(result.t, error, color="tab:red", label=label)
    _finish_line(result, [ax])
    ax.set_ylabel("TCP position error [mm]")
    if worst is not None and error[worst] > 0:
        ax.set_ylim(0.0, 1.3 * error[worst])  # room above the curve for the legend
    else:
        ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)


def tracking_figure(result) -> Figure:
    """Joint tracking error q_ref - q_meas, the TCP position error [mm] and the torque over the
    effort limit, against time."""
    figure = Figure(figsize=(11, 8.5), layout="constrained")
    error_ax, tcp_ax, torque_ax = figure.subplots(3, 1, sharex=True)
    for j in range(result.q_ref.shape[1]):
        scale, unit = (1e3, "mm") if result.joint_unit(j) == "m" else (1e3, "mrad")
        error_ax.plot(result.t, scale * (result.q_ref[:, j] - result.q_meas[:, j]), label=f"joint {j + 1} [{unit}]",
                      **joint_style(j))
        torque_ax.plot(result.t, result.tau[:, j] / result.effort_limit[j], label=f"joint {j + 1}", **joint_style(j))
    error_ax.set_ylabel("q_ref - q_meas [mrad or mm]" if result.joint_types and "prismatic" in result.joint_types
                        else "q_ref - q_meas [mrad]")
    _tcp_error_panel(result, tcp_ax)
    torque_ax.set_ylabel("effort / effort limit")
    torque_ax.set_xlabel("t [s]")
    _finish_line(result, [error_ax, torque_ax])
    for ax in (error_ax, tcp_ax, torque_ax):
        ax.grid(True, alpha=0.3)
        _legend(ax)
    figure.suptitle(f"{result.name}: tracking")
    return figure


def scaling_figure(result) -> Figure:
    """The scaling coefficient c(t); for a planner that does not scale its trajectory (c the
    same throughout), a note saying so on the panel."""
    figure = Figure(figsize=(8, 3), layout="constrained")
    ax = figure.subplots()
    ax.plot(result.t, result.scaling, label="c")
    _finish_line(result, [ax])
    if len(result.scaling) and np.all(result.scaling == result.scaling[0]):
        ax.text(0.5, 0.5, f"no trajectory scaling: constant {result.scaling[0]:g}", transform=ax.transAxes,
                ha="center", va="center", fontsize="large", color="dimgrey",
                bbox={"facecolor": "white", "edgecolor": "lightgrey"})
    ax.set_xlabel("t [s]")
    ax.set_ylabel("c")
    ax.set_ylim(-0.05, 1.05)
    ax.grid(True, alpha=0.3)
    _legend(ax)
    figure.suptitle(f"{result.name}: scaling coefficient")
    return figure


def tcp_path_figure(result) -> Figure:
    """Left, the measured and reference TCP paths in 3-D (base frame) with the waypoints and,
    for a planner that turns to the next waypoint inside a neighbourhood of each (the Pająk
    planner's ϵ), those neighbourhoods as spheres; right, the distance between the two paths
    [mm] against time, which the 3-D view's scale cannot show."""
    figure = Figure(figsize=(13, 6), layout="constrained")
    grid = figure.add_gridspec(1, 2, width_ratios=(3, 2))
    ax = figure.add_subplot(grid[0], projection="3d")
    ax.plot(*result.tcp_ref[:, :3].T, label="reference", linewidth=2)
    ax.plot(*result.tcp[:, :3].T, "--", label="measured", linewidth=1)
    if len(result.waypoints):
        ax.scatter(*result.waypoints.T, color="tab:orange", s=60, label="waypoints")
    if len(result.waypoints) > 1 and np.isfinite(result.waypoint_neighbourhood):
        _draw_neighbourhoods(result, ax)
    if len(result.tcp_ref):
        ax.scatter(*result.tcp_ref[0, :3], color="tab:green", marker="^", s=90, label="start", depthshade=False)
        ax.scatter(*result.tcp_ref[-1, :3], color="black", marker="x", s=60, label="end")
    points = np.vstack([result.tcp_ref[:, :3], result.tcp[:, :3], result.waypoints.reshape(-1, 3)])
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
    _tcp_error_panel(result, error_ax)
    error_ax.set_xlabel("t [s]")
    error_ax.legend(loc="upper left", fontsize="small")
    error_ax.set_title("the measured TCP off the reference")
    figure.suptitle(f"{result.name}: TCP path")
    return figure


def _draw_neighbourhoods(result, ax) -> None:
    """Translucent spheres of radius ``result.waypoint_neighbourhood`` [m] around every waypoint
    but the last (where the task ends instead)."""
    radius = result.waypoint_neighbourhood
    azimuth, polar = np.meshgrid(np.linspace(0, 2 * np.pi, 25), np.linspace(0, np.pi, 13))
    unit = np.array([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar), np.cos(polar)])
    for k, centre in enumerate(result.waypoints[:-1]):
        ax.plot_surface(*(centre[:, None, None] + radius * unit), color="tab:orange", alpha=0.15, linewidth=0,
                        label=f"neighbourhood, ϵ = {1e3 * radius:g} mm" if k == 0 else None)


def figures_of(result) -> dict[str, Figure]:
    """The figures of ``result`` by file stem: joints, tracking, scaling and tcp_path."""
    return {"joints": joint_figure(result), "tracking": tracking_figure(result), "scaling": scaling_figure(result),
            "tcp_path": tcp_path_figure(result)}


def save_figures(result, directory) -> list[Path]:
    """Write joints.png, tracking.png, scaling.png and tcp_path.png of ``result`` into ``directory``
    (created if needed); returns the paths."""
    directory = output_folder(directory)
    paths = []
    for stem, figure in figures_of(result).items():
        path = directory / f"{stem}.png"
        figure.savefig(path, dpi=110)
        paths.append(path)
    return paths
