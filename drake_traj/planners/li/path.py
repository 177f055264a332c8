"""The closed test path of Li et al. 2019's Fig. 6 (:func:`li_closed_path`), in the robot's base
frame [m]."""

import math

import numpy as np

__all__ = ["li_closed_path"]

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
