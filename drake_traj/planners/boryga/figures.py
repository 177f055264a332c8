"""The paper's figures 5-7 for a loop path (matplotlib, imported when a figure is drawn)."""

import numpy as np

from drake_traj.planners.boryga.path import LoopPath
from drake_traj.validation import positive_scalar

__all__ = ["loop_path_figure"]


def loop_path_figure(plan: LoopPath, *, clock_rate: float = 1.0, samples: int = 4001):
    """The paper's figs. 5-7 for ``plan`` as run at the constant clock rate ``clock_rate`` (the
    planner's speed cap; 1: the path's own profile at v_max): position, velocity and acceleration
    per axis and their norms (speed along the path, acceleration magnitude) against time, junctions
    marked. At rate c the tool is at the path's point tau at t = tau / c, with velocity × c and
    acceleration × c²."""
    from matplotlib.figure import Figure

    c = positive_scalar(clock_rate, "clock_rate", "")
    tau = np.linspace(0.0, plan.duration, samples)
    position, velocity, acceleration = plan.sample(tau)[:3]
    t, velocity, acceleration = tau / c, velocity * c, acceleration * c * c
    figure = Figure(figsize=(9, 8), layout="constrained")
    axes = figure.subplots(3, 1, sharex=True)
    for ax, data, label, norm_label in (
        (axes[0], position, "position [m]", None),
        (axes[1], velocity, "velocity [m/s]", "speed"),
        (axes[2], acceleration, "acceleration [m/s$^2$]", "|a|"),
    ):
        for k, axis in enumerate("xyz"):
            ax.plot(t, data[:, k], label=axis)
        if norm_label:
            ax.plot(t, np.linalg.norm(data, axis=1), "k--", label=norm_label)
        for index, (time, name) in enumerate(zip(plan.breakpoints / c, ("B", "M", "T1", "T2", "M", "E"))):
            ax.axvline(time, color="grey", linewidth=0.6)
            if ax is axes[0]:  # alternate heights: M and T1 (T2 and M) are close on a small loop
                ax.annotate(name, (time, 1.0 + 0.07 * (index % 2)), xycoords=("data", "axes fraction"), ha="center",
                            va="bottom")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(ncol=4, fontsize="small")
    axes[-1].set_xlabel("t [s]")
    if c < 1.0:
        figure.suptitle(f"as run: the path's profile at v_max slowed to c = {c:.4g} by the joint limits "
                        "(t = τ / c, velocity × c, acceleration × c²)", fontsize="medium")
    return figure
