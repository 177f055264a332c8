"""The Pająk 2024 law's discrete update and its fixed-step integrator, compiled.

:func:`update_kernel` is the law's discrete update (the eq. 18 anchor, the waypoint switching of
eq. 19 or stop-and-go, the progress monitor), :func:`finished_kernel` its finish test and
:func:`integrate_kernel` a whole task with RK4; each evaluates the law through
:func:`~.kernel.evaluate_kernel`, on the flat vectors whose layouts are :mod:`.kernel`'s enums
(:class:`~.kernel.Parameter`, :class:`~.kernel.Discrete`, :class:`~.kernel.Evaluation`,
:class:`~.kernel.Log`; the result a :class:`~.kernel.Status`), with the arm's kinematic data
``model`` and its TCP ``tool`` (4, 4) as there. :mod:`.law` wraps the update for Python callers
(the Drake system, tests) and :mod:`.integration` the integrator for whole runs.

Equation numbers in comments are Pająk 2024's; docs/papers.md explains the corrections and our
improvements (each a flag of the parameters).
"""

import math

import numpy as np

from drake_traj.compiled import compiled, sources_digest
from drake_traj.planners.pajak import kernel
from drake_traj.planners.pajak.kernel import (Discrete, Evaluation, Log, Parameter, Status, evaluate_kernel,
                                              kinematics_into, orientation_error)
from drake_traj.planners.pajak.limits import BRAKE_LAG, BRAKE_SLEW, brake_weight
from drake_traj.planners.pajak.terms import ORIENTATION_LENGTH, blend_progress

__all__ = ["finished_kernel", "integrate_kernel", "update_kernel"]

_EVALUATION_SIZE = int(Evaluation.SIZE)  # a plain int for np.empty in compiled code

# As in :mod:`.kernel` (numba issue #1833): the functions below call the law of kernel.py, so each
# that reaches compiled code of another module closes over the digest of kernel.py and of every
# source the law reaches (``dependencies``, unused otherwise); they call each other through the
# module's globals.
DEPENDENCY_SOURCES = (kernel.__file__, *kernel.DEPENDENCY_SOURCES)
_DEPENDENCIES = sources_digest(*DEPENDENCY_SOURCES)


@compiled
def _position_distance(pose, waypoints, i):
    """|x - p_i| of the TCP position [m]."""
    return math.sqrt((pose[0] - waypoints[i, 0]) ** 2 + (pose[1] - waypoints[i, 1]) ** 2
                     + (pose[2] - waypoints[i, 2]) ** 2)


@compiled
def _finite(values) -> bool:
    for value in values:
        if not math.isfinite(value):
            return False
    return True


def _pose_reached(dependencies):
    @compiled
    def pose_reached(pose, waypoint, p, out) -> bool:
        """The whole pose within the accuracies of ``waypoint``: |x - p| < ε and the angle of
        R_pᵀ R below the orientation accuracy (the paper's |e| < ε over all six components of e);
        the errors into out[POSITION_ERROR], out[ORIENTATION_ERROR]."""
        dependencies  # noqa: B018 (numba's cache key, see above)
        position = math.sqrt((pose[0] - waypoint[0]) ** 2 + (pose[1] - waypoint[1]) ** 2
                             + (pose[2] - waypoint[2]) ** 2)
        orientation = orientation_error(pose[3:], waypoint[3:])
        out[Evaluation.POSITION_ERROR] = position
        out[Evaluation.ORIENTATION_ERROR] = orientation
        return position < p[Parameter.ACCURACY] and orientation < p[Parameter.ORIENTATION_ACCURACY]

    return pose_reached


pose_reached = _pose_reached(_DEPENDENCIES)


def _update_kernel(dependencies):
    @compiled
    def update_kernel(t, q, qd, d, p, model, tool, waypoints, remaining, out):
        """The discrete update at time t, in place on ``d``; returns a :class:`~.kernel.Status`.

        Evaluates the law first (into ``out``, with the discrete state before the update);
        records the eq. 18 anchor (t0, c0) = (t, c) when the limits set c, and c and the braking
        weight for their rate limits; switches waypoints (eq. 19 blending, or stop-and-go with c
        restarting from 0 when the acceleration is limited); tracks progress (out[REMAINING])
        and reports a finish, a stall, gimbal lock or non-finite values.
        """
        dependencies  # noqa: B018 (numba's cache key, see above)
        evaluate_kernel(t, q, qd, d, p, model, tool, waypoints, out)
        pose = out[Evaluation.POSE:Evaluation.POSE + 6]
        bad = not (_finite(out[Evaluation.QDD:Evaluation.QDD + 6]) and _finite(q) and _finite(qd))
        c = out[Evaluation.C]
        if p[Parameter.LIMIT_ACCELERATION] > 0.0:
            if abs(c - out[Evaluation.C_RELAXED]) > 1e-12:  # the limits moved c off eq. 18: new anchor
                d[Discrete.T0] = t
                d[Discrete.C0] = c
                d[Discrete.HELD_BY] = out[Evaluation.HOLDING]  # which joint's limit (a stall's cause)
                d[Discrete.HELD_BY_VELOCITY] = out[Evaluation.HOLDING_VELOCITY]
            weight, target = brake_weight(out[Evaluation.VIOLATION], d[Discrete.BRAKE], d[Discrete.BRAKE_SLOPE],
                                          max(t - d[Discrete.T_UPDATE], 0.0))
            if abs(target - weight) < 1e-6:  # settled: exactly on the target (0 when the fallback is over)
                weight = target
            d[Discrete.BRAKE] = weight
            d[Discrete.BRAKE_SLOPE] = min(max((target - weight) / BRAKE_LAG, -BRAKE_SLEW), BRAKE_SLEW)
            d[Discrete.SATURATED] += out[Evaluation.SATURATED]
        d[Discrete.C] = c
        d[Discrete.APPROACH] = out[Evaluation.APPROACH]
        d[Discrete.ERROR:Discrete.ERROR + 3] = out[Evaluation.ERROR:Evaluation.ERROR + 3]
        d[Discrete.FINAL_ERROR:Discrete.FINAL_ERROR + 3] = out[Evaluation.FINAL_ERROR:Evaluation.FINAL_ERROR + 3]
        d[Discrete.BRANCH] = 1.0
        d[Discrete.T_UPDATE] = t
        i = int(d[Discrete.WAYPOINT])
        last = int(p[Parameter.NUM_WAYPOINTS]) - 1
        if p[Parameter.BLEND_WAYPOINTS] > 0.0:
            blending = d[Discrete.BLENDING] > 0.5
            _, step = blend_progress(pose, d[Discrete.X_REF:Discrete.X_REF + 3], d[Discrete.TRAVEL],
                                     p[Parameter.BLEND_DISTANCE])
            d[Discrete.TRAVEL] = d[Discrete.TRAVEL] + step if blending else 0.0
            d[Discrete.X_REF:Discrete.X_REF + 3] = pose[:3]
            d[Discrete.SIGMA] = out[Evaluation.SIGMA] if blending else 0.0
            if p[Parameter.CONTINUOUS_SWITCHING] > 0.0:
                switch = blending and out[Evaluation.SIGMA] >= 1.0  # the target is p_{i+1} already
            else:  # literal: when the TCP leaves the ball
                switch = blending and _position_distance(pose, waypoints, i) >= p[Parameter.NEIGHBOURHOOD]
            if switch:
                i += 1
                d[Discrete.WAYPOINT] = i
                d[Discrete.BLENDING] = 0.0
                d[Discrete.SIGMA] = 0.0
            # entering the ball of p_i (i < w): blend towards p_{i+1} from σ = 0
            if d[Discrete.BLENDING] < 0.5 and i < last and \
                    _position_distance(pose, waypoints, i) < p[Parameter.NEIGHBOURHOOD]:
                d[Discrete.BLENDING] = 1.0
                d[Discrete.TRAVEL] = 0.0
                d[Discrete.SIGMA] = 0.0
        elif i < last and pose_reached(pose, waypoints[i], p, out):
            # stop at each waypoint: the pose reached at low TCP speed, then the next task starts
            # from rest (with c from 0 again when the acceleration is limited)
            jac = np.empty((6, 6))
            kinematics_into(model, q, qd, tool, np.empty(6), jac, np.empty(6))
            speed = 0.0
            for k in range(3):
                rate = 0.0
                for j in range(6):
                    rate += jac[k, j] * qd[j]
                speed += rate * rate
            if math.sqrt(speed) < p[Parameter.STOP_SPEED]:
                i += 1
                d[Discrete.WAYPOINT] = i
                if p[Parameter.LIMIT_ACCELERATION] > 0.0:
                    d[Discrete.T0] = t
                    d[Discrete.C0] = 0.0
                    d[Discrete.C] = 0.0
                    d[Discrete.APPROACH] = 0.0  # a new approach (with c = 0, b does not move q̈)
                d[Discrete.BRANCH] = 0.0  # a new target: its shortest branch
        if p[Parameter.LIMIT_ACCELERATION] > 0.0 and p[Parameter.BOUNDED_SCALING] > 0.0:
            # the jerk limit's reference: q̈ with the updated state, so that the update itself
            # does not move q̈ (an unreached limit leaves the law as it is)
            after = np.empty(_EVALUATION_SIZE)
            evaluate_kernel(t, q, qd, d, p, model, tool, waypoints, after)
            d[Discrete.QDD:Discrete.QDD + 6] = after[Evaluation.QDD:Evaluation.QDD + 6]
            d[Discrete.QDD_TIME] = t
        finished = pose_reached(pose, waypoints[i], p, out) and i >= last
        # progress monitor: remaining path = distance to p_i (+ weighted orientation) + the rest
        left = out[Evaluation.POSITION_ERROR] + ORIENTATION_LENGTH * out[Evaluation.ORIENTATION_ERROR] + remaining[i]
        out[Evaluation.REMAINING] = left
        if left < d[Discrete.BEST] - 1e-4:
            d[Discrete.BEST] = left
            d[Discrete.T_BEST] = t
        if bad:
            return Status.NON_FINITE
        if out[Evaluation.COS_PITCH] < p[Parameter.MIN_COS_PITCH]:
            return Status.SINGULAR
        if finished:
            return Status.FINISHED
        if t - d[Discrete.T_BEST] > p[Parameter.STALL_TIME]:
            return Status.STALL
        return Status.RUNNING

    return update_kernel


update_kernel = _update_kernel(_DEPENDENCIES)


def _finished_kernel(dependencies):
    @compiled
    def finished_kernel(q, d, p, model, tool, waypoints) -> bool:
        """True once p_w is the active target and the whole pose is within the accuracies of it."""
        dependencies  # noqa: B018 (numba's cache key, see above)
        i = int(d[Discrete.WAYPOINT])
        if i < int(p[Parameter.NUM_WAYPOINTS]) - 1:
            return False
        pose = np.empty(6)
        kinematics_into(model, q, np.zeros(6), tool, pose, np.empty((6, 6)), np.empty(6))
        return pose_reached(pose, waypoints[i], p, np.empty(_EVALUATION_SIZE))

    return finished_kernel


finished_kernel = _finished_kernel(_DEPENDENCIES)


def _integrate_kernel(dependencies):
    @compiled
    def integrate_kernel(q0, d0, dt, steps, settle_steps, p, model, tool, waypoints, remaining, log, peak, out, final):
        """Integrate one task from rest at ``q0`` with RK4 at a fixed step ``dt``, updating the
        discrete state (from ``d0``) every step.

        At every step k: discrete update at t_k, then the sample (row k of ``log``, layout
        :class:`~.kernel.Log`), then an RK4 step with the discrete state held (its first stage is the
        sample). Stops ``settle_steps`` steps after the first sample where the task is finished,
        at a failure, or after ``steps`` steps. ``peak`` (2, 6) gets max |q̇| and max |q̈| per
        joint over every evaluation (RK4 stages included); ``out`` the last evaluation; ``final``
        [q; q̇; d] (12 + Discrete.SIZE) at the last step, after its update.

        Returns:
            (samples logged, status, finish index or -1): status is FINISHED once finished
            (later failures ignored), else the failure (STALL, SINGULAR, NON_FINITE) or TIMEOUT.
        """
        dependencies  # noqa: B018 (numba's cache key, see above)
        q = q0.copy()
        qd = np.zeros(6)
        d = d0.copy()
        finish = -1
        stage_q = np.empty((4, 6))
        stage_qd = np.empty((4, 6))
        stage_qdd = np.empty((4, 6))
        for k in range(steps + settle_steps + 1):
            t = k * dt
            status = update_kernel(t, q, qd, d, p, model, tool, waypoints, remaining, out)
            final[:6] = q
            final[6:12] = qd
            final[12:] = d
            if status < 0 and finish < 0:
                return k, status, finish
            stage_q[0] = q
            stage_qd[0] = qd
            for s in range(4):  # RK4 stages at t, t + dt/2, t + dt/2, t + dt
                h = (0.0, 0.5 * dt, 0.5 * dt, dt)[s]
                if s > 0:
                    stage_q[s] = q + h * stage_qd[s - 1]
                    stage_qd[s] = qd + h * stage_qdd[s - 1]
                evaluate_kernel(t + h, stage_q[s], stage_qd[s], d, p, model, tool, waypoints, out)
                stage_qdd[s] = out[Evaluation.QDD:Evaluation.QDD + 6]
                for j in range(6):
                    peak[0, j] = max(peak[0, j], abs(stage_qd[s, j]))
                    peak[1, j] = max(peak[1, j], abs(stage_qdd[s, j]))
                if s > 0:
                    continue
                if out[Evaluation.COS_PITCH] < p[Parameter.MIN_COS_PITCH]:
                    return k, Status.SINGULAR, finish
                if not _finite(stage_qdd[0]):
                    return k, Status.NON_FINITE, finish
                row = log[k]
                row[Log.T] = t
                row[Log.Q:Log.Q + 6] = q
                row[Log.QD:Log.QD + 6] = qd
                row[Log.QDD:Log.QDD + 6] = stage_qdd[0]
                row[Log.C] = out[Evaluation.C]
                row[Log.TCP:Log.TCP + 6] = out[Evaluation.POSE:Evaluation.POSE + 6]
                row[Log.SATURATED] = out[Evaluation.SATURATED]
                row[Log.DISCRETE:Log.DISCRETE + Discrete.SIZE] = d
                if status == Status.FINISHED and finish < 0:
                    finish = k
                if finish >= 0 and k >= finish + settle_steps:
                    return k + 1, Status.FINISHED, finish
                if finish < 0 and k >= steps:
                    return k + 1, Status.TIMEOUT, finish
            for j in range(6):
                q[j] += dt / 6.0 * (stage_qd[0, j] + 2.0 * stage_qd[1, j] + 2.0 * stage_qd[2, j] + stage_qd[3, j])
                qd[j] += dt / 6.0 * (stage_qdd[0, j] + 2.0 * stage_qdd[1, j] + 2.0 * stage_qdd[2, j]
                                     + stage_qdd[3, j])
        return steps + settle_steps + 1, Status.TIMEOUT, finish

    return integrate_kernel


integrate_kernel = _integrate_kernel(_DEPENDENCIES)
