"""The trajectory-scaling coefficient c(t) shared by every planner.

Pająk 2024, eq. 18: after the last change at t0, where c had the value c0, the
coefficient relaxes exponentially back to 1:  c(t) = (c0 - 1) exp(-(t - t0)) + 1.
We generalise the target 1 to a ``goal`` (the speed override, in [0, 1]) and keep a rate
[1/s] (1 in the paper). The closed forms below let a planner evaluate c, dc/dt and the
scaled clock at any time without integrating them.
"""

from __future__ import annotations

import math

import numpy as np

from drake_traj.compiled import compiled


@compiled
def relaxed_scaling(t: float, t0: float, c0: float, goal: float = 1.0, rate: float = 1.0):
    """(c, dc/dt) at time t [s] of eq. 18 generalised: c = (c0 - goal) exp(-rate (t - t0)) + goal.

    Compiled (:mod:`drake_traj.compiled`): the Pająk 2024 law calls it on every evaluation."""
    decay = math.exp(-rate * (t - t0))
    return (c0 - goal) * decay + goal, -rate * (c0 - goal) * decay


def scaled_clock(t, t0: float, c0: float, goal: float = 1.0, rate: float = 1.0):
    """Integral of c from t0 to t [s]: the planner-clock advance under eq. 18 scaling."""
    elapsed = np.asarray(t, dtype=float) - t0
    return goal * elapsed + (c0 - goal) * (1.0 - np.exp(-rate * elapsed)) / rate
