"""Planner systems under one contract (:mod:`.base`), each with its config dataclass and ``make``.

The scenario's ``planner`` entry is one of :data:`PLANNER_CONFIGS` (a YAML tag names the type,
e.g. ``planner: !PajakConfig {...}``); :func:`make_planner` builds the system it describes.

One layout for every planner package (quintic, pajak, boryga, li, smooth, free):

- ``config.py``: the config dataclass (the scenario's entry; no ``from __future__ import
  annotations``: pydrake's YAML reader reads the field types) with ``validate(robot=UR10E)``, the
  config's own checks for the robot it runs on, as ``make`` runs them first (same errors, same
  order, same messages); it returns the config checked (a copy with its arrays normalised for
  Pająk, Boryga and Li, else the config itself);
- the law module(s): the paper's math, plain numpy where it can be (``law.py``, and ``profile.py``,
  ``path.py``, ``kernel.py``, ``search.py``, ... where the method has more parts);
- ``system.py``: the LeafSystem and ``make(config, robot, q_initial)``, which calls ``validate``
  first (Pająk's law checks the robot before it calls ``validate``, and the free-motion planner
  validates in its constructor, which ``make`` calls first);
- ``__init__.py``: exports the config and ``make`` (smooth has two planners: both configs in its
  ``config.py``, ``make_smooth_waypoints`` and ``make_retimed_pajak`` in its ``system.py``).

The baselines (:mod:`.baselines`) are one module each with the same parts in that order (law,
system, config with ``validate``, ``make``). No planner package imports another, but for the
re-timed Pająk planner (smooth), which times the Pająk planner's path: what they share is in
:mod:`.base` (the contract, the goals and the joint-move limits of a config), :mod:`.laws` (pure
time laws) and :mod:`.timing` (the timing of any joint path). Every maker is registered in
``_MAKERS`` below, the one registry.
"""

from __future__ import annotations

from typing import Union

from drake_traj.planners import boryga, free, li, pajak, quintic, smooth
from drake_traj.planners.base import PlannerSystem, planner_robot, release_system
from drake_traj.planners.baselines import MovejConfig, RuckigConfig, ToppraConfig, movej, ruckig, toppra
from drake_traj.planners.boryga import BorygaConfig
from drake_traj.planners.free import FreeMotionConfig
from drake_traj.planners.li import LiConfig
from drake_traj.planners.pajak import PajakConfig
from drake_traj.planners.quintic import QuinticConfig
from drake_traj.planners.smooth import RetimedPajakConfig, SmoothWaypointsConfig
from drake_traj.robots.base import Robot
from drake_traj.validation import finite_array, instance_of

__all__ = [
    "BorygaConfig", "FreeMotionConfig", "LiConfig", "MovejConfig", "PLANNER_CONFIGS", "PajakConfig", "PlannerConfig", "PlannerSystem",
    "QuinticConfig", "RetimedPajakConfig", "RuckigConfig", "SmoothWaypointsConfig", "ToppraConfig", "make_planner",
    "release_system",
]

# Each config type and the ``make(config, robot, q_initial)`` that builds its planner.
_MAKERS = {
    QuinticConfig: quintic.make,
    PajakConfig: pajak.make,
    BorygaConfig: boryga.make,
    LiConfig: li.make,
    MovejConfig: movej.make,
    RuckigConfig: ruckig.make,
    ToppraConfig: toppra.make,
    SmoothWaypointsConfig: smooth.make_smooth_waypoints,
    RetimedPajakConfig: smooth.make_retimed_pajak,
    FreeMotionConfig: free.make,
}
PLANNER_CONFIGS = tuple(_MAKERS)
PlannerConfig = Union[QuinticConfig, PajakConfig, BorygaConfig, LiConfig, MovejConfig, RuckigConfig, ToppraConfig,
                      SmoothWaypointsConfig, RetimedPajakConfig, FreeMotionConfig]


def make_planner(config: PlannerConfig, robot: Robot | None = None, q_initial=None) -> PlannerSystem:
    """The planner system ``config`` describes, on ``robot``, starting at rest at ``q_initial``
    [rad, or m for a prismatic joint], (num_joints,); both are needed (left out, a TypeError says
    what to pass). Its :attr:`~drake_traj.planners.base.PlannerSystem.robot` is ``robot`` (a
    station runs it there and refuses another robot). A scenario's planner is
    ``drake_traj.make_planner(scenario)``."""
    try:
        maker = _MAKERS[type(config)]
    except KeyError:
        raise TypeError(f"config must be one of {[c.__name__ for c in PLANNER_CONFIGS]}, got {type(config).__name__}: "
                        f"{config!r:.80}; a scenario's planner is drake_traj.make_planner(scenario), a config's "
                        "drake_traj.planners.make_planner(config, robot, q_initial)") from None
    missing = [name for name, value in (("robot", robot), ("q_initial", q_initial)) if value is None]
    if missing:
        raise TypeError(f"make_planner({type(config).__name__}(...), robot, q_initial) needs {' and '.join(missing)}: "
                        "the robot it runs on and its start configuration [rad], e.g. robot = drake_traj.get_robot('ur10e'); "
                        "make_planner(config, robot, robot.home_configuration)")
    instance_of(robot, Robot, "robot")
    planner = maker(config, robot, finite_array(q_initial, "q_initial", "rad or m", shape=(robot.num_joints,)))
    planner.robot = planner_robot(robot, planner.num_joints)
    return planner
