"""Free motion: goals reached on a path found through the cell (OMPL's planners, our shortcutting,
the smooth timing, the cell check): :class:`FreeMotionConfig`, :class:`FreeMotionPlanner`."""

from drake_traj.planners.free.planner import FreeMotionConfig, FreeMotionPlanner, make
from drake_traj.planners.free.search import PLANNERS, Scene, SearchResult, search, shortcut

__all__ = ["FreeMotionConfig", "FreeMotionPlanner", "PLANNERS", "Scene", "SearchResult", "make", "search", "shortcut"]
