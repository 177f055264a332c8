"""The UR e-Series closed form, compiled: k(q), the analytic Jacobian and J̇q̇ of the TCP of any
e-Series arm, whose lengths are data (``model`` = [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6]).

The hot path of the task-space planners: :func:`drake_traj.robots.compiled_kinematics.task_kinematics_into`
dispatches here, and :class:`drake_traj.robots.ur_eseries.URArm` calls it for its kinematics.
"""

import math

import numpy as np

from drake_traj.compiled import compiled, sources_digest
from drake_traj.robots import task_space
from drake_traj.robots.task_space import tcp_rows_into, velocity_product_terms

__all__ = ["UR_CLOSED_FORM", "kinematics_into", "singularity_measure_many"]

# The compiled functions below that call task_space's close over its digest, numba's cache key
# (drake_traj.compiled): an edit of task_space.py recompiles them.
_DEPENDENCIES = sources_digest(task_space.__file__)

# model[0] of the closed form's data [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6] (kinematics_into)
UR_CLOSED_FORM = 0.0

# --------------------------------------------------------------------------------------------
# Closed-form k(q), analytic J(q) and J̇q̇: the hot path of the task-space planners, compiled.
# --------------------------------------------------------------------------------------------


@compiled
def _singularity_factors(model, s3, s5, c2, c23, s234):
    # det J_g = a2 a3 s3 s5 (a2 c2 + a3 c23 + d5 s234): elbow, wrist and shoulder factors.
    a2, a3, d5 = model[2], model[3], model[5]
    shoulder = (a2 * c2 + a3 * c23 + d5 * s234) / (abs(a2) + abs(a3))
    return min(abs(s3), abs(s5), abs(shoulder))


def _kinematics_into_with(dependencies):
    @compiled
    def kinematics_into(model, q, qd, tool, pose, jac, bias):
        """k(q) into ``pose`` (6), the analytic J into ``jac`` (6, 6) and J̇q̇ into ``bias`` (6) of the
        TCP; returns (cos φ_Y, singularity measure). Compiled; the kernel of :meth:`URArm.kinematics`.

        ``model`` is the closed form's data [UR_CLOSED_FORM, d1, a2, a3, d4, d5, d6] [m] (an arm's
        :attr:`URData.model`); ``tool`` (4, 4) is X_FT, the TCP in the flange frame F (``tool0``). The
        standard-DH chain of :meth:`URArm.dh_frames` written out: joint axes z_j at origins o_j, flange o_6;
        J_g columns z_j x (o_6 - o_j) and z_j; the bias (q̈ = 0) by
        :func:`~drake_traj.robots.task_space.velocity_product_terms`; the TCP and the Euler-angle rows by :func:`~drake_traj.robots.task_space.tcp_rows_into`.
        """
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        c1, s1 = math.cos(q[0]), math.sin(q[0])
        c2, s2 = math.cos(q[1]), math.sin(q[1])
        c5, s5 = math.cos(q[4]), math.sin(q[4])
        c6, s6 = math.cos(q[5]), math.sin(q[5])
        q23 = q[1] + q[2]
        q234 = q23 + q[3]
        c23, s23 = math.cos(q23), math.sin(q23)
        c234, s234 = math.cos(q234), math.sin(q234)
        # joint axes z_0..z_5 (z_1 = z_2 = z_3) and the link vectors r_j = o_{j+1} - o_j
        axes = np.empty((6, 3))
        links = np.empty((6, 3))
        axes[0, 0], axes[0, 1], axes[0, 2] = 0.0, 0.0, 1.0
        for j in range(1, 4):
            axes[j, 0], axes[j, 1], axes[j, 2] = s1, -c1, 0.0
        x4 = (c1 * c234, s1 * c234, s234)
        axes[4, 0], axes[4, 1], axes[4, 2] = c1 * s234, s1 * s234, -c234
        axes[5, 0], axes[5, 1], axes[5, 2] = c5 * s1 - s5 * x4[0], -c5 * c1 - s5 * x4[1], -s5 * s234
        x5 = (c5 * x4[0] + s5 * s1, c5 * x4[1] - s5 * c1, c5 * s234)
        links[0, 0], links[0, 1], links[0, 2] = 0.0, 0.0, model[1]
        links[1, 0], links[1, 1], links[1, 2] = model[2] * c1 * c2, model[2] * s1 * c2, model[2] * s2
        links[2, 0], links[2, 1], links[2, 2] = model[3] * c1 * c23, model[3] * s1 * c23, model[3] * s23
        links[3, 0], links[3, 1], links[3, 2] = model[4] * s1, -model[4] * c1, 0.0
        for k in range(3):
            links[4, k] = model[5] * axes[4, k]
            links[5, k] = model[6] * axes[5, k]
        # J_v column j = z_j x (o_6 - o_j), accumulating o_6 - o_j from the flange back
        p0 = p1 = p2 = 0.0
        for j in range(5, -1, -1):
            p0 += links[j, 0]
            p1 += links[j, 1]
            p2 += links[j, 2]
            jac[0, j] = axes[j, 1] * p2 - axes[j, 2] * p1
            jac[1, j] = axes[j, 2] * p0 - axes[j, 0] * p2
            jac[2, j] = axes[j, 0] * p1 - axes[j, 1] * p0
        omega, alpha, acceleration = np.empty(3), np.empty(3), np.empty(3)
        velocity_product_terms(axes, links, qd, omega, alpha, acceleration)  # the bias (q̈ = 0)
        # the flange's rotation R_F = [x6 y6 z6]: x6 = c6 x5 - s6 z4, y6 = -s6 x5 - c6 z4, z6 = z5
        rotation = np.empty((3, 3))
        for k in range(3):
            rotation[k, 0] = c6 * x5[k] - s6 * axes[4, k]
            rotation[k, 1] = -s6 * x5[k] - c6 * axes[4, k]
            rotation[k, 2] = axes[5, k]
        cy = tcp_rows_into(rotation, axes, np.array((p0, p1, p2)), omega, alpha, acceleration, tool, pose, jac, bias)
        return cy, _singularity_factors(model, math.sin(q[2]), s5, c2, c23, s234)

    return kinematics_into


kinematics_into = _kinematics_into_with(_DEPENDENCIES)


@compiled
def singularity_measure_many(model, q, out):
    for k in range(q.shape[0]):
        out[k] = _singularity_factors(model, math.sin(q[k, 2]), math.sin(q[k, 4]), math.cos(q[k, 1]),
                                      math.cos(q[k, 1] + q[k, 2]), math.sin(q[k, 1] + q[k, 2] + q[k, 3]))
