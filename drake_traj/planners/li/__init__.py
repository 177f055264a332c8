"""Li, Zhang, Zhou 2019: the Cartesian stage (:mod:`.cartesian`: break-point limits, look-ahead,
seven-case cubic ACC/DEC), the joint stage (:mod:`.joint`: re-timing, quintic B-spline, exact
joint-limit check), our limit repair (:mod:`.repair`: tool check through FK, smooth time warp), the
whole pipeline (:mod:`.plan`), the closed test path of Fig. 6 (:mod:`.path`), the planner system
(:mod:`.system`), its figure (:mod:`.figures`) and the config with ``make`` (:mod:`.config`)."""

from drake_traj.planners.li.config import LiConfig, make

__all__ = ["LiConfig", "make"]
