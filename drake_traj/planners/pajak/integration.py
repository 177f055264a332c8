"""Fixed-step RK4 integration of the Pająk 2024 law outside Drake: :func:`integrate` for one task
(tests, the preflight and benchmarks) and :func:`integrate_many` for a batch of tasks."""

from __future__ import annotations

import math

import numpy as np

from drake_traj.errors import PlanningError
from drake_traj.planners.pajak.law import _CAUSES, SATURATED, WAYPOINT, DISCRETE_SIZE, PajakLaw
from drake_traj.robots import ur10e as robot

__all__ = ["integrate", "integrate_many"]


def _rk4_step(law, t, q, qd, d, dt, k1a, peak):
    """One RK4 step of (q, q̇)' = (q̇, q̈) with the discrete state held; k1a = q̈(t, q, q̇).
    ``peak`` (6,) accumulates max |q̈| over the stages."""
    h = 0.5 * dt
    k2v = qd + h * k1a
    k2a = law._evaluate(t + h, q + h * qd, k2v, d).qdd
    k3v = qd + h * k2a
    k3a = law._evaluate(t + h, q + h * k2v, k3v, d).qdd
    k4v = qd + dt * k3a
    k4a = law._evaluate(t + dt, q + dt * k3v, k4v, d).qdd
    np.maximum(peak, np.abs(k2a[0]), out=peak)
    np.maximum(peak, np.abs(k3a[0]), out=peak)
    np.maximum(peak, np.abs(k4a[0]), out=peak)
    q_new = q + dt / 6.0 * (qd + 2.0 * k2v + 2.0 * k3v + k4v)
    qd_new = qd + dt / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a)
    return q_new, qd_new


def integrate(law: PajakLaw, q0, *, dt: float = 1e-3, t_max: float = 30.0, settle_time: float = 0.0,
              raise_on_timeout: bool = True) -> dict:
    """Integrate one task with RK4 at a fixed step, updating the discrete state every step.

    At every step k: discrete update at t_k, then the sample (t_k, q_k, q̇_k, q̈_k, c_k, TCP,
    waypoint), then an RK4 step with the discrete state held (its first stage is the sample).
    Stops at the first sample where the task is finished, or ``settle_time`` later (to look at
    what happens after the finish, e.g. an overshoot).

    Args:
        law: a single-task :class:`PajakLaw`.
        q0: initial joint positions [rad], (6,); the arm starts at rest.
        dt: step [s].
        t_max: give up after this long [s].
        settle_time: keep integrating this long after the finish [s].
        raise_on_timeout: False returns what was computed up to t_max (T = nan) instead of
            raising (to look at the start of a motion).

    Returns:
        dict of arrays: t (K,), q, qd, qdd (K, 6), c (K,), tcp (K, 6) pose, waypoint (K,),
        saturated (K,) bool, discrete (K, DISCRETE_SIZE); and T (finish time [s]), finish_index,
        error (TCP position error at the finish [m]) and stage_peak (6,): max |q̈| over every
        evaluation, RK4 stages included.

    Raises:
        PlanningError: singularity, no progress, non-finite values or not finished by t_max;
            ``.partial`` holds the arrays computed so far.
    """
    if not law.single:
        raise ValueError("law must be a single-task PajakLaw (use integrate_many for batches)")
    if not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive number of seconds, got {dt}")
    if not np.isfinite(t_max) or t_max <= 0:
        raise ValueError(f"t_max must be a positive number of seconds, got {t_max}")
    if not np.isfinite(settle_time) or settle_time < 0:
        raise ValueError(f"settle_time must be a non-negative number of seconds, got {settle_time}")
    q = law._batch(robot._as_joint_vector(q0, "q0"), 6).copy()
    qd = np.zeros_like(q)
    d = law._batch(law.initial_discrete(), DISCRETE_SIZE)
    steps = int(math.ceil(t_max / dt))
    names = ("t", "q", "qd", "qdd", "c", "tcp", "waypoint", "saturated", "discrete")
    log = {name: [] for name in names}
    peak = np.zeros(6)

    def partial():
        out = {k: np.array(v) for k, v in log.items()}
        out["stage_peak"] = peak.copy()
        return out

    t = 0.0
    finish_time = finish_index = final_error = None
    for k in range(steps + int(math.ceil(settle_time / dt)) + 1):
        t = k * dt
        try:
            d, status, message = law._update(t, q, qd, d)
            if status[0] < 0 and finish_time is None:
                raise PlanningError(message[0], time=t, configuration=q[0], cause=_CAUSES[int(status[0])])
            ev = law._evaluate(t, q, qd, d)
            law._check(t, q[0], ev, 0)
        except PlanningError as exc:
            exc.partial = partial()
            raise
        except (np.linalg.LinAlgError, FloatingPointError) as exc:
            raise PlanningError(
                f"numerical failure: {exc}", time=t, configuration=q[0], cause="non-finite", partial=partial()
            ) from exc
        np.maximum(peak, np.abs(ev.qdd[0]), out=peak)
        for name, value in zip(
            names,
            (t, q[0].copy(), qd[0].copy(), ev.qdd[0].copy(), float(ev.c[0]), ev.pose[0].copy(),
             int(d[0, WAYPOINT]), bool(ev.saturated[0]), d[0].copy()),
        ):
            log[name].append(value)
        if status[0] == 1 and finish_time is None:
            finish_time = t
            finish_index = len(log["t"]) - 1
            final_error = float(np.linalg.norm(ev.pose[0, :3] - law.waypoints[0, law.num_waypoints[0] - 1, :3]))
        if finish_time is not None and t >= finish_time + settle_time - 1e-12:
            break
        if finish_time is None and k >= steps:
            if raise_on_timeout:
                raise PlanningError(
                    f"the task did not finish within t_max = {t_max} s", time=t, configuration=q[0],
                    cause="timeout", partial=partial(),
                )
            break
        try:
            q, qd = _rk4_step(law, t, q, qd, d, dt, ev.qdd, peak)
        except (np.linalg.LinAlgError, FloatingPointError) as exc:
            raise PlanningError(
                f"numerical failure: {exc}", time=t, configuration=q[0], cause="non-finite", partial=partial()
            ) from exc
    out = partial()
    out["T"] = np.nan if finish_time is None else finish_time
    out["finish_index"] = finish_index
    out["error"] = np.nan if final_error is None else final_error
    return out


def integrate_many(law: PajakLaw, q0, *, dt: float = 2e-3, t_max: float = 30.0) -> list[dict]:
    """Integrate a batch of tasks at once (RK4, vectorised over tasks), without raising.

    Each task stops when it finishes or fails; the batch is compacted to the running tasks as
    they end. Nothing is stored per sample; the summary per task has: status ("finished" or
    the failure cause), message, T, error (final TCP distance to p_w [m]), q (final), and
    max_velocity_ratio = max |q̇|/q̇_max and max_acceleration_ratio = max |q̈|/q̈_max over every
    evaluated sample (RK4 stages included), c_range (min, max of c over the same samples),
    saturated (updates with the improvement-2 fallback), nan (a non-finite value was seen).
    """
    if law.single:
        raise ValueError("law must be a batch PajakLaw (built from a sequence of parameters)")
    if not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive number of seconds, got {dt}")
    q = np.array(q0, dtype=float)
    if q.shape != (law.count, 6):
        raise ValueError(f"q0 must have shape ({law.count}, 6), got {q.shape}")
    parameters = list(law.parameters)
    active = np.arange(law.count)  # original index of each row of the current batch
    qd = np.zeros_like(q)
    d = law.initial_discrete()
    result = [
        dict(status="timeout", message=f"the task did not finish within t_max = {t_max} s", T=np.nan,
             error=np.nan, q=None, max_velocity_ratio=0.0, max_acceleration_ratio=0.0, saturated=0, nan=False)
        for _ in range(law.count)
    ]
    vel_ratio = np.zeros(law.count)
    acc_ratio = np.zeros(law.count)
    nan = np.zeros(law.count, dtype=bool)
    c_min = np.full(law.count, np.inf)
    c_max = np.full(law.count, -np.inf)
    steps = int(math.ceil(t_max / dt))
    current = law

    def stage(t_s, q_s, qd_s):
        ev = current._evaluate(t_s, q_s, qd_s, d)
        qdd = ev.qdd
        c_min[active] = np.fmin(c_min[active], ev.c)
        c_max[active] = np.fmax(c_max[active], ev.c)
        ok = np.all(np.isfinite(qdd), axis=1)
        nan[active[~ok]] = True
        ratio = np.max(np.abs(qdd) / current.qdd_max, axis=1)
        acc_ratio[active] = np.maximum(acc_ratio[active], np.where(ok, ratio, np.inf))
        return np.where(ok[:, None], qdd, 0.0)

    t = 0.0
    with np.errstate(all="ignore"):
        for k in range(steps + 1):
            t = k * dt
            d, status, message = current._update(t, q, qd, d)
            vel_ratio[active] = np.maximum(vel_ratio[active], np.max(np.abs(qd) / current.qd_max, axis=1))
            ended = np.flatnonzero(status != 0)
            if ended.size:
                pose, *_ = robot.ur10e_kinematics(q[ended], qd[ended])
                for row, j in enumerate(ended):
                    r = result[active[j]]
                    r["status"] = "finished" if status[j] == 1 else _CAUSES[int(status[j])]
                    r["message"] = message[j]
                    r["T"] = t
                    goal = current.waypoints[j, current.num_waypoints[j] - 1, :3]
                    r["error"] = float(np.linalg.norm(pose[row, :3] - goal))
                    r["q"] = q[j].copy()
                    r["saturated"] = int(d[j, SATURATED])
                keep = status == 0
                if not keep.any():
                    active = active[keep]
                    break
                active, q, qd, d = active[keep], q[keep], qd[keep], d[keep]
                current = PajakLaw([parameters[j] for j in active])
            h = 0.5 * dt
            k1a = stage(t, q, qd)
            k2v = qd + h * k1a
            k2a = stage(t + h, q + h * qd, k2v)
            k3v = qd + h * k2a
            k3a = stage(t + h, q + h * k2v, k3v)
            k4v = qd + dt * k3a
            k4a = stage(t + dt, q + dt * k3v, k4v)
            q = q + dt / 6.0 * (qd + 2 * k2v + 2 * k3v + k4v)
            qd = qd + dt / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a)
    for row, j in enumerate(active):  # still running at t_max
        result[j]["T"] = t
        result[j]["q"] = q[row].copy()
        result[j]["saturated"] = int(d[row, SATURATED])
    for j in range(law.count):
        result[j]["max_velocity_ratio"] = float(vel_ratio[j])
        result[j]["max_acceleration_ratio"] = float(acc_ratio[j])
        result[j]["nan"] = bool(nan[j])
        result[j]["c_range"] = (float(c_min[j]), float(c_max[j]))
    return result
