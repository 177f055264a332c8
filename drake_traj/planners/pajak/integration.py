"""Fixed-step RK4 integration of the Pająk 2024 law outside Drake: :func:`integrate` runs one
task (the planner's preflight, tests and benchmarks) with the compiled
:func:`~.stepping.integrate_kernel`."""

from __future__ import annotations

import math

import numpy as np

from drake_traj.errors import Cause, PlanningError
from drake_traj.planners.pajak.kernel import Discrete, Evaluation, Log, Status
from drake_traj.planners.pajak.law import PajakLaw
from drake_traj.planners.pajak.stepping import integrate_kernel
from drake_traj.validation import finite_array, invalid

__all__ = ["integrate"]


def integrate(law: PajakLaw, q0, *, dt: float = 1e-3, t_max: float = 30.0, settle_time: float = 0.0,
              raise_on_timeout: bool = True, check_reach: bool = True) -> dict:
    """Integrate one task with RK4 at a fixed step, updating the discrete state every step.

    At every step k: discrete update at t_k, then the sample (t_k, q_k, q̇_k, q̈_k, c_k, TCP,
    waypoint), then an RK4 step with the discrete state held (its first stage is the sample).
    Stops at the first sample where the task is finished, or ``settle_time`` later (to look at
    what happens after the finish, e.g. an overshoot).

    Args:
        law: the task's :class:`PajakLaw`.
        q0: initial joint positions [rad], (6,); the arm starts at rest.
        dt: step [s].
        t_max: give up after this long [s].
        settle_time: keep integrating this long after the finish [s].
        raise_on_timeout: False returns what was computed up to t_max (T = nan) instead of
            raising (to look at the start of a motion).
        check_reach: refuse a waypoint out of reach before integrating (False: integrate until the
            law itself fails there, e.g. stalls; what a run without a preflight meets).

    Returns:
        dict of arrays: t (K,), q, qd, qdd (K, 6), c (K,), tcp (K, 6) pose, waypoint (K,),
        saturated (K,) bool, discrete (K, Discrete.SIZE); T (finish time [s]), finish_index,
        error (TCP position error at the finish [m]), orientation_error (angle of R_goalᵀ R at
        the finish [rad]), stage_peak (6,): max |q̈| and stage_velocity_peak (6,): max |q̇| over
        every evaluation, RK4 stages included.

    Raises:
        PlanningError: a waypoint out of reach (before integrating), singularity, no progress,
            non-finite values or not finished by t_max; ``.partial`` holds the arrays computed so
            far.
    """
    if not isinstance(law, PajakLaw):
        raise ValueError(f"law must be a PajakLaw, got {type(law).__name__}")
    for name, value, low in (("dt", dt, 0.0), ("t_max", t_max, 0.0)):
        if not np.isfinite(value) or value <= low:
            raise invalid(name, f"{name} must be a positive number of seconds, got {value}")
    if not np.isfinite(settle_time) or settle_time < 0:
        raise ValueError(f"settle_time must be a non-negative number of seconds, got {settle_time}")
    q0 = finite_array(q0, "q0", "rad", shape=(law.robot.num_joints,))
    unreachable = law.reach_failure(q0) if check_reach else None
    if unreachable is not None:
        raise unreachable
    steps = int(math.ceil(t_max / dt - 1e-9))
    settle_steps = int(math.ceil(settle_time / dt - 1e-9))
    log = np.empty((steps + settle_steps + 1, Log.SIZE))
    peak = np.zeros((2, 6))
    out = np.zeros(Evaluation.SIZE)
    final = np.zeros(12 + Discrete.SIZE)  # [q; q̇; discrete] at the last step
    count, status, finish = integrate_kernel(q0, law.initial_discrete(), float(dt), steps, settle_steps, law.vector,
                                             law.model, law.tool, law.waypoints, law.remaining, log, peak, out, final)
    log = log[:count]
    result = {
        "t": log[:, Log.T], "q": log[:, Log.Q:Log.Q + 6], "qd": log[:, Log.QD:Log.QD + 6],
        "qdd": log[:, Log.QDD:Log.QDD + 6], "c": log[:, Log.C], "tcp": log[:, Log.TCP:Log.TCP + 6],
        "waypoint": log[:, Log.DISCRETE + Discrete.WAYPOINT].astype(int), "saturated": log[:, Log.SATURATED] > 0.5,
        "discrete": log[:, Log.DISCRETE:Log.DISCRETE + Discrete.SIZE], "stage_peak": peak[1].copy(),
        "stage_velocity_peak": peak[0].copy(),
    }
    if status != Status.FINISHED:
        if status == Status.TIMEOUT:
            if not raise_on_timeout:
                return result | {"T": np.nan, "finish_index": None, "error": np.nan, "orientation_error": np.nan}
            error = PlanningError(f"the task did not finish within t_max = {t_max} s", time=float(log[-1, Log.T]),
                                  configuration=final[:6].copy(), cause=Cause.TIMEOUT)
        else:  # failed at step ``count``, before its sample
            error = law.failure(status, count * dt, final[:6], final[12:], out)
        error.partial = result
        raise error
    goal = law.waypoints[-1]
    position, orientation = law.kinematics.pose_error(result["tcp"][finish], goal)
    return result | {"T": float(result["t"][finish]), "finish_index": int(finish), "error": position,
                     "orientation_error": orientation}
