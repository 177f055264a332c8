"""The arrays a :class:`~drake_traj.results.result.SimulationResult` holds: their names and shapes.

The logged arrays (:data:`ARRAY_NAMES`) are time-major, one row per sample on the uniform grid
``t`` [s]; the limits (:data:`LIMIT_NAMES`) are the planner's per joint and its task waypoints
(m, base frame).
"""

__all__ = ["ARRAY_NAMES", "LIMIT_NAMES", "SHAPES"]

ARRAY_NAMES = ("t", "q_ref", "qd_ref", "qdd_ref", "q_meas", "qd_meas", "tau", "scaling", "tcp", "tcp_ref")
LIMIT_NAMES = ("velocity_limit", "acceleration_limit", "effort_limit", "waypoints")
# The shape of each array of a result, N samples of n joints (checked by SimulationResult).
SHAPES = {"t": ("N",), **{name: ("N", "n") for name in ("q_ref", "qd_ref", "qdd_ref", "q_meas", "qd_meas", "tau")},
          "scaling": ("N",), "tcp": ("N", 6), "tcp_ref": ("N", 6), "velocity_limit": ("n",),
          "acceleration_limit": ("n",), "effort_limit": ("n",), "waypoints": (None, 3), "goal": (6,)}
