"""Free motion: goals reached on a path found through the cell (OMPL's planners, our shortcutting,
the smooth timing, the cell check): :class:`FreeMotionConfig`, :class:`FreeMotionPlanner`.

Modules, as in every planner package: :mod:`.config` (:class:`FreeMotionConfig` and its
``validate``), :mod:`.search` (the path search and shortcutting), :mod:`.law` (the legs and their
motion as a time law) and :mod:`.system` (:class:`FreeMotionPlanner` and ``make``)."""

from drake_traj.planners.free.config import MAX_GOALS, MAX_PLANNING_TIME, FreeMotionConfig
from drake_traj.planners.free.law import FreeMotionLaw, Leg
from drake_traj.planners.free.search import PLANNERS, Scene, SearchResult, search, shortcut
from drake_traj.planners.free.system import DENSITIES, FreeMotionPlanner, make

__all__ = [
    "DENSITIES", "FreeMotionConfig", "FreeMotionLaw", "FreeMotionPlanner", "Leg", "MAX_GOALS", "MAX_PLANNING_TIME",
    "PLANNERS", "Scene", "SearchResult", "make", "search", "shortcut",
]
