"""Smooth, jerk-limited, near-time-optimal timing of joint paths (:mod:`.timing`) and the two
planners built on it (:mod:`.planners`): through joint waypoints without stopping, and the joint
path of Pająk 2024's preflight re-timed. The method: docs/smooth_timing.md."""

from drake_traj.planners.smooth.timing import InfeasibleTimingError, SmoothTiming, check_path, exact_peaks, time_path

__all__ = ["InfeasibleTimingError", "SmoothTiming", "check_path", "exact_peaks", "time_path"]
