"""Meshcat extras: the task's waypoints and TCP path, and the standalone HTML recording."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform

from drake_traj.result import SimulationResult

WAYPOINT_COLOUR = Rgba(1.0, 0.55, 0.0, 0.5)
PATH_COLOUR = Rgba(0.9, 0.1, 0.1, 1.0)


def draw_task(meshcat: Meshcat, result: SimulationResult, *, waypoint_radius: float = 0.05) -> None:
    """Waypoint spheres (radius [m], default Pająk 2024's neighbourhood) and the measured TCP path."""
    meshcat.Delete("/drake_traj")
    for index, point in enumerate(result.waypoints):
        path = f"/drake_traj/waypoints/{index}"
        meshcat.SetObject(path, Sphere(waypoint_radius), WAYPOINT_COLOUR)
        meshcat.SetTransform(path, RigidTransform(np.asarray(point, dtype=float)))
    if len(result.tcp) > 1:
        meshcat.SetLine("/drake_traj/tcp_path", result.tcp[:, :3].T.copy(), 3.0, PATH_COLOUR)


def export_html(meshcat: Meshcat, path) -> Path:
    """Write the scene and its recording as one self-contained HTML file (no server needed).

    The camera is placed in front of and above the arm (base frame, z up) so the whole
    workspace in front of it is in view.
    """
    path = Path(path)
    meshcat.SetCameraPose(camera_in_world=[0.9, -1.6, 1.1], target_in_world=[-0.1, -0.4, 0.45])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(meshcat.StaticHtml())
    return path
