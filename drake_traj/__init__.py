"""drake_traj: published trajectory planners as Drake systems on a simulated UR10e.

The public API::

    from drake_traj import load_scenario, make_planner, simulate, SimulationResult
    scenario = load_scenario("pajak_sim3")  # a shipped name or a YAML file (and variant)
    result = simulate(scenario)             # drake-traj run without the files: preflight, run

Planner configs (``PajakConfig``, ``QuinticConfig``, ...) build planners with
:func:`drake_traj.planners.make_planner`; robots come from :func:`get_robot`.
"""

from drake_traj.station import add_station, build_station, make_station, run_station, simulate
from drake_traj.errors import Cause, DrakeTrajError, Failure, PlanningError, SingularConfigurationError
from drake_traj.planners import (BorygaConfig, FreeMotionConfig, LiConfig, MovejConfig, PajakConfig, QuinticConfig,
                                 RetimedPajakConfig, RuckigConfig, SmoothWaypointsConfig, ToppraConfig)
from drake_traj.result import Metrics, SimulationResult
from drake_traj.robots import Robot, get_robot
from drake_traj.scenario import ControllerGains, Scenario, SpeedOverride, load_scenario, make_planner, preflight
from drake_traj.version import __version__


__all__ = [
    "add_station", "BorygaConfig", "build_station", "Cause", "ControllerGains", "DrakeTrajError", "Failure",
    "FreeMotionConfig",
    "get_robot", "LiConfig", "load_scenario", "make_planner", "make_station", "Metrics", "MovejConfig",
    "PajakConfig", "PlanningError", "preflight", "QuinticConfig", "RetimedPajakConfig", "Robot", "RuckigConfig",
    "run_station", "Scenario", "simulate", "SimulationResult", "SingularConfigurationError", "SmoothWaypointsConfig",
    "SpeedOverride", "ToppraConfig",
]
