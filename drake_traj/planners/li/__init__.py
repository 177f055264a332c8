"""Li, Zhang, Zhou 2019: the Cartesian stage (:mod:`.cartesian`: break-point limits, look-ahead,
seven-case cubic ACC/DEC), the joint stage (:mod:`.joint`: re-timing, quintic B-spline, exact
joint-limit check), our limit repair (:mod:`.repair`: tool check through FK, smooth time warp), the
whole pipeline (:mod:`.plan`), the closed test path of Fig. 6 (:mod:`.path`), its figure
(:mod:`.figures`), the config with its ``validate`` (:mod:`.config`) and the planner system with
``make`` (:mod:`.system`)."""

from drake_traj.planners.li.config import LiConfig
from drake_traj.planners.li.system import LiPathPlanner, make

__all__ = ["LiConfig", "LiPathPlanner", "make"]
