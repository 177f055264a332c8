"""Timing of any joint path, shared by the planners that time one (smooth, free) and the Ruckig
baseline; no planner package is imported here (docs/smooth_timing.md for the method).

Modules, by job:

- :mod:`.path_timing`: :func:`time_path`, the jerk-limited, near-time-optimal timing of a joint
  path from rest to rest, over grids of more and more nodes;
- :mod:`.program`: its linear programs on one grid (HiGHS), :mod:`.grid`: the grids and the motion
  of a solution between the nodes (both internal to :func:`time_path`);
- :mod:`.motion`: the timed motion (:class:`SmoothTiming`), its exact peaks, the repair that
  stretches its time (:func:`stretched`) and :class:`InfeasibleTimingError`;
- :mod:`.paths`: the path given (:func:`check_path`, :func:`sample_path`) and the C2 spline
  through joint waypoints (:func:`waypoint_path`);
- :mod:`.limits`: the velocity, acceleration and jerk limits, the default jerk limit and a
  config's limits with the robot's defaults (:func:`jerk_limited_limits`);
- :mod:`.ruckig_law`: Ruckig's rest-to-rest moves as a time law (:class:`RuckigStopLaw`), and
  :mod:`.moves`: such moves as a :class:`SmoothTiming` (:func:`stop_timing`, :func:`line_timing`).

Joint positions in rad, limits in rad/s, rad/s² and rad/s³, times in s.
"""

from drake_traj.planners.timing.limits import (DEFAULT_JERK_FACTOR, check_least_durations, default_jerk_limit,
                                               jerk_limited_limits, joint_limits)
from drake_traj.planners.timing.motion import InfeasibleTimingError, SmoothTiming, exact_peaks, stretched
from drake_traj.planners.timing.moves import line_timing, stop_timing
from drake_traj.planners.timing.path_timing import GRID_LEVELS, MAX_GRID_POINTS, time_path
from drake_traj.planners.timing.paths import PATH_TOLERANCE, check_path, sample_path, waypoint_path
from drake_traj.planners.timing.ruckig_law import RuckigStopLaw

__all__ = [
    "DEFAULT_JERK_FACTOR", "GRID_LEVELS", "InfeasibleTimingError", "MAX_GRID_POINTS", "PATH_TOLERANCE", "RuckigStopLaw",
    "SmoothTiming", "check_least_durations", "check_path", "default_jerk_limit", "exact_peaks", "jerk_limited_limits",
    "joint_limits", "line_timing", "sample_path", "stop_timing", "stretched", "time_path", "waypoint_path",
]
