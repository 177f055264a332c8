"""Two planners built on the shared smooth timing (:mod:`drake_traj.planners.timing`): through
joint waypoints without stopping (:class:`SmoothWaypointsConfig`), and the joint path of Pająk
2024's preflight re-timed (:class:`RetimedPajakConfig`). The method: docs/smooth_timing.md.

Modules, as in every planner package: :mod:`.config` (both configs, each with ``validate``),
:mod:`.law` (their timed motions) and :mod:`.system` (:class:`SmoothPlanner` and both makers,
:func:`make_smooth_waypoints` and :func:`make_retimed_pajak`). The timing itself (``time_path``,
``SmoothTiming``, ...) is :mod:`drake_traj.planners.timing`'s, also importable from here."""

from drake_traj.planners.smooth.config import MAX_GOALS, RetimedPajakConfig, SmoothWaypointsConfig
from drake_traj.planners.smooth.law import pajak_joint_path, pajak_samples, timed, waypoints_timing
from drake_traj.planners.smooth.system import SmoothPlanner, make_retimed_pajak, make_smooth_waypoints
from drake_traj.planners.timing import InfeasibleTimingError, SmoothTiming, check_path, exact_peaks, time_path

__all__ = [
    "InfeasibleTimingError", "MAX_GOALS", "RetimedPajakConfig", "SmoothPlanner", "SmoothTiming", "SmoothWaypointsConfig",
    "check_path", "exact_peaks", "make_retimed_pajak", "make_smooth_waypoints", "pajak_joint_path", "pajak_samples",
    "time_path", "timed", "waypoints_timing",
]
