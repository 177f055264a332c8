"""What engineers use today, under the same planner contract, for ``drake-traj bench`` and
scenarios: UR-style MoveJ with radius blending (:mod:`.movej`), Ruckig's jerk-limited moves
(:mod:`.ruckig`) and Drake's time-optimal Toppra along a path (:mod:`.toppra`).

Layout: one module per baseline, not a package each. Each module holds, in this order, the same
parts as a planner package's modules: the law (MoveJ's blends, Toppra's path and table; Ruckig's
law is the shared timing's, :class:`~drake_traj.planners.timing.RuckigStopLaw`), the planner
system, the config with its ``validate(robot)`` and ``make(config, robot, q_initial)``. A baseline
is a thin shell around one library or one law (80 to 400 lines): split into four modules each, it
would be mostly imports. The three ``make`` share a name, so they are reached by module
(``baselines.movej.make``, as the registry in :mod:`drake_traj.planners` does); the configs and
systems are re-exported here."""

from drake_traj.planners.baselines import movej, ruckig, toppra
from drake_traj.planners.baselines.movej import MovejBlendLaw, MovejConfig, MovejPlanner, blend_radius_value, trapezoid_profile
from drake_traj.planners.baselines.ruckig import RuckigConfig, RuckigPlanner
from drake_traj.planners.baselines.toppra import (ToppraConfig, ToppraLaw, ToppraPlanner, geometric_path_from_samples,
                                                  time_optimal_along_path)

__all__ = [
    "MovejBlendLaw", "MovejConfig", "MovejPlanner", "RuckigConfig", "RuckigPlanner", "ToppraConfig", "ToppraLaw",
    "ToppraPlanner", "blend_radius_value", "geometric_path_from_samples", "movej", "ruckig", "time_optimal_along_path",
    "toppra", "trapezoid_profile",
]
