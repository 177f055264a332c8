"""drake_traj: published trajectory planners as Drake systems on a simulated UR10e.

The public API::

    from drake_traj import load_scenario, make_planner, simulate, SimulationResult
    scenario = load_scenario("pajak_sim3")  # a shipped name or a YAML file (and variant)
    result = simulate(scenario)             # drake-traj run without the files: preflight, run

Planner configs (``PajakConfig``, ``QuinticConfig``, ...) build planners with
:func:`drake_traj.planners.make_planner`; robots come from :func:`get_robot`.
"""

import importlib

# each public name -> the module it comes from, imported on first use (PEP 562): ``import
# drake_traj`` (and ``drake-traj --version``, whose module is in this package) does not import Drake,
# nor, until ``__version__`` is asked for, the installed package's metadata (``drake-traj`` handles
# Ctrl-C from its first moment, which comes after this package is imported)
_SOURCES = {
    **dict.fromkeys(("add_station", "build_station", "make_station", "run_station", "simulate"), "drake_traj.station"),
    **dict.fromkeys(("Cause", "DrakeTrajError", "Failure", "PlanningError", "SingularConfigurationError"),
                    "drake_traj.errors"),
    **dict.fromkeys(("BorygaConfig", "FreeMotionConfig", "LiConfig", "MovejConfig", "PajakConfig", "QuinticConfig",
                     "RetimedPajakConfig", "RuckigConfig", "SmoothWaypointsConfig", "ToppraConfig"), "drake_traj.planners"),
    **dict.fromkeys(("Metrics", "SimulationResult"), "drake_traj.results"),
    **dict.fromkeys(("Robot", "get_robot"), "drake_traj.robots"),
    **dict.fromkeys(("ControllerGains", "Scenario", "SpeedOverride", "load_scenario", "make_planner", "preflight"),
                    "drake_traj.scenario"),
}


__all__ = sorted(_SOURCES)
_SOURCES["__version__"] = "drake_traj.version"  # served the same way, not one of the API's names


def __getattr__(name: str):
    """A public name of :data:`__all__`, imported from its module on first use."""
    if name not in _SOURCES:
        raise AttributeError(f"module 'drake_traj' has no attribute {name!r}")
    value = getattr(importlib.import_module(_SOURCES[name]), name)
    globals()[name] = value  # the next use does not come here
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SOURCES))
