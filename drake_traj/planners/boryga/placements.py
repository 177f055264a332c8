"""The paper's example loop (Boryga, section 3 / Table 1) and its placement in the workspace of
each of Boryga's three robots."""

from dataclasses import dataclass, field

import numpy as np

from drake_traj.planners.boryga.path import plan_loop_path

__all__ = ["PAPER_LOOP", "PLACED_ROBOTS", "LoopPlacement", "paper_loop_placement"]

# Boryga, section 3 / Table 1: B, M, E [m], Delta [m], v_max [m/s]. Horizontal plane z = 1 m.
PAPER_LOOP = {
    "B": (0.5, 0.5, 1.0),
    "M": (0.54, 0.53, 1.0),
    "E": (0.54, 0.5, 1.0),
    "delta": 0.02,
    "v_max": 0.25,
}


@dataclass(frozen=True, eq=False)
class LoopPlacement:
    """The paper's loop (same shape, Delta and v_max) moved into one robot's workspace.

    Attributes:
        robot: robot name.
        B, M, E: placed points [m], read-only arrays (3,).
        delta: Delta [m]; v_max: loop speed [m/s] (the paper's).
        offset: translation applied to the paper's Table 1 points [m] (no rotation is needed).
        reason: where the loop was put and why.
    """

    robot: str
    B: np.ndarray
    M: np.ndarray
    E: np.ndarray
    delta: float
    v_max: float
    offset: np.ndarray
    reason: str = field(default="")

    def plan(self):
        """The placed loop as a time law, :func:`plan_loop_path`."""
        return plan_loop_path(self.B, self.M, self.E, self.v_max, delta=self.delta)


_PLACEMENT = {
    # Pure translation, so the loop keeps its shape, plane (horizontal), Delta and v_max.
    "anthropomorphic": (
        (-0.2, -0.2, -0.5),
        "translated by (-0.2, -0.2, -0.5) m: B = (0.3, 0.3, 0.5), M = (0.34, 0.33, 0.5), "
        "E = (0.34, 0.3, 0.5). The paper's path is 0.97-1.03 m from the shoulder against a 0.78 m "
        "reach (docs/papers.md); here the whole loop is 0.46-0.53 m from the shoulder (59-68 % of the "
        "reach), 0.17 m above it, in front of the arm near the diagonal x = y as in the paper: the "
        "elbow stays bent at 95-109 deg, far from the stretched/folded singularities, the joint-1 "
        "axis and every joint limit.",
    ),
    "scara": (
        (0.0, 0.0, -0.735),
        "translated down by 0.735 m to z = 0.265 m (mid-stroke lambda3 = 0.1 m); x and y are the "
        "paper's, so theta1 and theta2 follow the paper's plan. At the paper's z = 1 m the stroke "
        "would be -0.635 m (docs/papers.md); the horizontal distances 0.71-0.78 m are inside the annulus "
        "0.12-0.96 m, with theta2 between about -86 and -71 deg (arm well bent, far from its limits).",
    ),
    "cartesian": (
        (0.0, 0.0, 0.0),
        "not moved: the paper's points are inside the chosen joint ranges (lambda1 = 0.76 m, "
        "lambda2 = 0.5-0.55 m, lambda3 = -s_x = -0.5 to -0.56 m).",
    ),
}


def paper_loop_placement(robot_name: str) -> LoopPlacement:
    """The paper's example loop (Table 1, Delta = 0.02 m, v_max = 0.25 m/s) placed for a robot.

    Returns:
        LoopPlacement with B, M, E, delta, v_max, the offset from Table 1 and the reason.
    """
    if robot_name not in _PLACEMENT:
        raise ValueError(f"robot must be one of Boryga's {tuple(_PLACEMENT)}, got {robot_name!r}")
    offset, reason = _PLACEMENT[robot_name]
    offset = np.array(offset, dtype=float)
    points = []
    for key in ("B", "M", "E"):
        point = np.array(PAPER_LOOP[key], dtype=float) + offset
        point.setflags(write=False)
        points.append(point)
    offset.setflags(write=False)
    return LoopPlacement(
        robot=robot_name,
        B=points[0],
        M=points[1],
        E=points[2],
        delta=PAPER_LOOP["delta"],
        v_max=PAPER_LOOP["v_max"],
        offset=offset,
        reason=reason,
    )


PLACED_ROBOTS = tuple(_PLACEMENT)  # the robots with a placement of the paper's loop
