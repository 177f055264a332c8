"""The compiled kinematics of a packed serial chain (:meth:`~drake_traj.robots.chain.SerialChain.packed`)
and its numerical inverse kinematics: k(q), the analytic Jacobian, J̇q̇ and the singularity measure
of any 6-axis arm of revolute joints (:func:`chain_kinematics_into`, the ``model`` kind
:data:`CHAIN` of :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`, so the
compiled Pająk 2024 law runs on it unchanged), and every joint solution of a TCP pose
(:func:`inverse_kinematics_all`, :func:`inverse_kinematics_near`). Base frame, metres and radians
throughout.

The packed ``model`` is [CHAIN, L, the 7 fixed transforms X_{M(i-1) F(i)} (i = 1..6) and
X_{M6 T0} of the flange (rotation row-major 9, translation 3), the 6 unit joint axes (3)]: the
frames of :class:`~drake_traj.robots.chain.SerialChain`, L its characteristic length [m].

The singularity measure of a chain is the cube root of the Hadamard ratio
|det J̃| / Π_j ‖J̃ column j‖ of the flange's geometric Jacobian J̃ = [J_v / L; J_ω], its linear rows
divided by the chain's characteristic length L (the sum of the lengths of its fixed translations,
stored in the model). The ratio is in [0, 1] (Hadamard's inequality), 1 when the six joint twists
are mutually orthogonal, zero exactly at a singular J_g, and independent of the tool (a TCP offset
adds a multiple of the angular rows to the linear ones, leaving det J_g as it is; the flange's
columns are used). The cube root: an industrial 6R arm's det J_g is a product of three factors
(shoulder, elbow and wrist; a2 a3 s3 s5 h on the UR10e), so the root is on the scale of one factor,
the scale of the UR closed form's measure (the smallest factor) that the Pająk law's
singularity threshold (0.1) was set on. Measured on 2000 random UR10e configurations: quantiles
10/50/90 % of 0.071/0.19/0.30 against the closed form's 0.037/0.24/0.61, below 0.1 for 18 % of
them against 26 %; the plain ratio is below 0.1 at every one of them (median 0.0064).

The compiled functions that run on a packed chain live in this one module (numba keys each
cached function on its own source file, :mod:`drake_traj.compiled`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from drake_traj.compiled import compiled, sources_digest
from drake_traj.errors import SingularConfigurationError, UnreachablePoseError, joint_label
from drake_traj.robots.base import FLANGE, format_point
from drake_traj.robots import task_space
from drake_traj.robots.task_space import rotation_from_zyx_euler, tcp_rows_into, velocity_product_terms, wrap_angle
from drake_traj.validation import finite_array

__all__ = ["CHAIN", "chain_kinematics_into", "chain_reach", "chain_singularity_factors", "inverse_kinematics_all",
           "inverse_kinematics_near"]

# The compiled functions below that call task_space's close over its digest, numba's cache key
# (drake_traj.compiled): an edit of task_space.py recompiles them.
_DEPENDENCIES = sources_digest(task_space.__file__)

NUM_JOINTS = 6
CHAIN = 1.0  # model[0] of a serial chain (compiled_kinematics.task_kinematics_into)
# model layout: [CHAIN, L, 7 transforms (R row-major 9, p 3), 6 axes (3)]
_LENGTH = 1
_TRANSFORMS = 2
_AXES = _TRANSFORMS + 12 * (NUM_JOINTS + 1)

IK_SEEDS = 256  # quasi-random Newton starts per pose (Sobol points within the joint limits)
IK_ITERATIONS = 80  # Newton / Levenberg-Marquardt steps per start, at most
IK_TOLERANCE = 1e-10  # [m and rad], a start has converged when its pose error is below this
# singularity measure below which an IK solution is singular (a Hadamard ratio of 1e-9: the
# solutions on a singular continuum converge to |sin q5| ~ 1e-12 on the UR10e, measure ~ 1e-4)
IK_SINGULAR_TOLERANCE = 1e-3
IK_DISTINCT = 1e-6  # [rad], solutions closer than this (modulo 2 pi, every joint) are one


# --------------------------------------------------------------------------------------------
# Compiled kinematics of a packed chain.
# --------------------------------------------------------------------------------------------


@compiled
def _chain_frames(model, q, axes, origins, rotation, flange):
    """The joint axes z_j into ``axes`` (6, 3) and their origins o_j into ``origins`` (6+, 3), the
    flange's rotation R_BF into ``rotation`` (3, 3) and origin into ``flange`` (3), all in the
    base frame [m], of the packed chain ``model`` at q [rad]. Scalars throughout (no arrays
    allocated: this is the hot path of the compiled law)."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0  # R_B,M(i-1)
    p0 = p1 = p2 = 0.0
    for i in range(NUM_JOINTS + 1):
        k = _TRANSFORMS + 12 * i
        m00, m01, m02 = model[k], model[k + 1], model[k + 2]
        m10, m11, m12 = model[k + 3], model[k + 4], model[k + 5]
        m20, m21, m22 = model[k + 6], model[k + 7], model[k + 8]
        t0, t1, t2 = model[k + 9], model[k + 10], model[k + 11]
        p0, p1, p2 = (p0 + r00 * t0 + r01 * t1 + r02 * t2, p1 + r10 * t0 + r11 * t1 + r12 * t2,
                      p2 + r20 * t0 + r21 * t1 + r22 * t2)
        # R_B,F(i) = R_B,M(i-1) X_{M(i-1) F(i)}'s rotation
        f00, f01, f02 = r00 * m00 + r01 * m10 + r02 * m20, r00 * m01 + r01 * m11 + r02 * m21, \
            r00 * m02 + r01 * m12 + r02 * m22
        f10, f11, f12 = r10 * m00 + r11 * m10 + r12 * m20, r10 * m01 + r11 * m11 + r12 * m21, \
            r10 * m02 + r11 * m12 + r12 * m22
        f20, f21, f22 = r20 * m00 + r21 * m10 + r22 * m20, r20 * m01 + r21 * m11 + r22 * m21, \
            r20 * m02 + r21 * m12 + r22 * m22
        if i == NUM_JOINTS:
            rotation[0, 0], rotation[0, 1], rotation[0, 2] = f00, f01, f02
            rotation[1, 0], rotation[1, 1], rotation[1, 2] = f10, f11, f12
            rotation[2, 0], rotation[2, 1], rotation[2, 2] = f20, f21, f22
            break
        a0, a1, a2 = model[_AXES + 3 * i], model[_AXES + 3 * i + 1], model[_AXES + 3 * i + 2]
        z0, z1, z2 = f00 * a0 + f01 * a1 + f02 * a2, f10 * a0 + f11 * a1 + f12 * a2, f20 * a0 + f21 * a1 + f22 * a2
        axes[i, 0], axes[i, 1], axes[i, 2] = z0, z1, z2
        origins[i, 0], origins[i, 1], origins[i, 2] = p0, p1, p2
        # R_B,M(i) = R_B,F(i) Rot(a, q) = c R + s [z]x R + (1 - c) z aᵀ (Rodrigues, [Ra]x R = R [a]x)
        c, s = math.cos(q[i]), math.sin(q[i])
        v = 1.0 - c
        r00 = c * f00 + s * (z1 * f20 - z2 * f10) + v * z0 * a0
        r10 = c * f10 + s * (z2 * f00 - z0 * f20) + v * z1 * a0
        r20 = c * f20 + s * (z0 * f10 - z1 * f00) + v * z2 * a0
        r01 = c * f01 + s * (z1 * f21 - z2 * f11) + v * z0 * a1
        r11 = c * f11 + s * (z2 * f01 - z0 * f21) + v * z1 * a1
        r21 = c * f21 + s * (z0 * f11 - z1 * f01) + v * z2 * a1
        r02 = c * f02 + s * (z1 * f22 - z2 * f12) + v * z0 * a2
        r12 = c * f12 + s * (z2 * f02 - z0 * f22) + v * z1 * a2
        r22 = c * f22 + s * (z0 * f12 - z1 * f02) + v * z2 * a2
    flange[0], flange[1], flange[2] = p0, p1, p2


@compiled
def _eliminate(matrix, rhs):
    """Gaussian elimination with partial pivoting of the square ``matrix`` to upper triangular
    form, the same row operations on ``rhs`` (both overwritten); returns det ``matrix`` (0.0, and
    the elimination stopped, for a singular one)."""
    n = matrix.shape[0]
    det = 1.0
    for col in range(n):
        pivot = col
        for row in range(col + 1, n):
            if abs(matrix[row, col]) > abs(matrix[pivot, col]):
                pivot = row
        if matrix[pivot, col] == 0.0:
            return 0.0
        if pivot != col:
            for k in range(n):
                matrix[col, k], matrix[pivot, k] = matrix[pivot, k], matrix[col, k]
            rhs[col], rhs[pivot] = rhs[pivot], rhs[col]
            det = -det
        det *= matrix[col, col]
        for row in range(col + 1, n):
            factor = matrix[row, col] / matrix[col, col]
            for k in range(col, n):
                matrix[row, k] -= factor * matrix[col, k]
            rhs[row] -= factor * rhs[col]
    return det


@compiled
def _hadamard_ratio(linear, axes, length):
    """(|det J̃| / Π‖J̃ columns‖)^(1/3) for J̃ = [J_v / length; J_ω], J_v the rows 0-2 of
    ``linear`` (3+, 6) and J_ω = ``axes``ᵀ (6, 3): in [0, 1], zero exactly at a singular J_g (the
    module docstring)."""
    scaled = np.empty((6, 6))
    product = 1.0
    for j in range(6):
        norm = 0.0
        for k in range(3):
            scaled[k, j] = linear[k, j] / length
            scaled[3 + k, j] = axes[j, k]
            norm += scaled[k, j] ** 2 + axes[j, k] ** 2
        product *= math.sqrt(norm)
    return min(1.0, abs(_eliminate(scaled, np.zeros(6))) / product) ** (1.0 / 3.0)


def _chain_kinematics_into_with(dependencies):
    @compiled
    def chain_kinematics_into(model, q, qd, tool, pose, jac, bias):
        """k(q) into ``pose`` (6), the analytic J into ``jac`` (6, 6) and J̇q̇ into ``bias`` (6) of the
        TCP ``tool`` (X_FT, 4x4) of the packed chain ``model``
        (:meth:`~drake_traj.robots.chain.SerialChain.packed`) at q [rad], q̇ [rad/s]; returns
        (cos φ_Y, singularity measure) — the contract of
        :func:`drake_traj.robots.ur_closed_form.kinematics_into`, base frame, metres and radians.

        Joint axes z_j at origins o_j and the flange by the chain product; J_v columns
        z_j x (o_F - o_j); the bias by :func:`~drake_traj.robots.task_space.velocity_product_terms`
        along r_j = o_{j+1} - o_j (o_6 the flange); the measure (the Hadamard
        ratio's cube root, module docstring) from the flange's columns; the TCP and Euler rows by
        :func:`~drake_traj.robots.task_space.tcp_rows_into`.
        """
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        axes, origins = np.empty((6, 3)), np.empty((7, 3))
        rotation, flange = np.empty((3, 3)), np.empty(3)
        _chain_frames(model, q, axes, origins, rotation, flange)
        origins[6, 0], origins[6, 1], origins[6, 2] = flange[0], flange[1], flange[2]
        for j in range(6):
            d0, d1, d2 = flange[0] - origins[j, 0], flange[1] - origins[j, 1], flange[2] - origins[j, 2]
            jac[0, j] = axes[j, 1] * d2 - axes[j, 2] * d1
            jac[1, j] = axes[j, 2] * d0 - axes[j, 0] * d2
            jac[2, j] = axes[j, 0] * d1 - axes[j, 1] * d0
        links = np.empty((6, 3))
        for j in range(6):
            for k in range(3):
                links[j, k] = origins[j + 1, k] - origins[j, k]
        omega, alpha, acceleration = np.empty(3), np.empty(3), np.empty(3)
        velocity_product_terms(axes, links, qd, omega, alpha, acceleration)  # the bias (q̈ = 0)
        measure = _hadamard_ratio(jac, axes, model[_LENGTH])
        cy = tcp_rows_into(rotation, axes, flange, omega, alpha, acceleration, tool, pose, jac, bias)
        return cy, measure

    return chain_kinematics_into


chain_kinematics_into = _chain_kinematics_into_with(_DEPENDENCIES)


def _measure(model, q, tool=FLANGE) -> float:
    """The singularity measure of the packed chain ``model`` at one configuration q [rad] (6,)
    (:func:`chain_kinematics_into`; batches: :func:`~drake_traj.robots.compiled_kinematics.task_kinematics`)."""
    return chain_kinematics_into(np.ascontiguousarray(model, dtype=float), np.asarray(q, dtype=float),
                                 np.zeros(NUM_JOINTS), np.ascontiguousarray(tool, dtype=float), np.empty(6),
                                 np.empty((6, 6)), np.empty(6))[1]


def chain_singularity_factors(model, q) -> dict[str, tuple[float, str]]:
    """{"jacobian": (measure, meaning)} at one configuration q [rad] (6,) of the packed chain
    ``model``: its one factor, the cube root of the Hadamard ratio of the scaled geometric
    Jacobian (module docstring), in [0, 1] and zero at a singular J (the TaskKinematics contract)."""
    measure = float(_measure(model, q))
    return {"jacobian": (measure, "the six joint twists near linear dependence (|det J| / product of its scaled "
                                  "column norms near 0)")}


# --------------------------------------------------------------------------------------------
# Numerical inverse kinematics.
# --------------------------------------------------------------------------------------------


@compiled
def _solve6(matrix, rhs, out):
    """out = matrix⁻¹ rhs (6x6, :func:`_eliminate` then back substitution; both overwritten);
    False for a singular matrix."""
    if _eliminate(matrix, rhs) == 0.0:
        return False
    for row in range(5, -1, -1):
        total = rhs[row]
        for k in range(row + 1, 6):
            total -= matrix[row, k] * out[k]
        out[row] = total / matrix[row, row]
    return True


@compiled
def _tcp_error(model, q, tool, goal, jac, error):
    """The SE(3) error of the TCP at q from ``goal`` (4x4 X_BT) into ``error`` (6): [p_goal - p;
    the rotation vector of R_goal R_Tᵀ] [m, rad] (base frame), the TCP's geometric Jacobian into
    ``jac`` (6, 6); returns |error| (2-norm)."""
    axes, origins = np.empty((6, 3)), np.empty((6, 3))
    rotation, flange = np.empty((3, 3)), np.empty(3)
    _chain_frames(model, q, axes, origins, rotation, flange)
    tcp = np.empty(3)
    rt = np.empty((3, 3))
    for a in range(3):
        tcp[a] = flange[a] + rotation[a, 0] * tool[0, 3] + rotation[a, 1] * tool[1, 3] + rotation[a, 2] * tool[2, 3]
        for b in range(3):
            rt[a, b] = rotation[a, 0] * tool[0, b] + rotation[a, 1] * tool[1, b] + rotation[a, 2] * tool[2, b]
    for j in range(6):
        d0, d1, d2 = tcp[0] - origins[j, 0], tcp[1] - origins[j, 1], tcp[2] - origins[j, 2]
        jac[0, j] = axes[j, 1] * d2 - axes[j, 2] * d1
        jac[1, j] = axes[j, 2] * d0 - axes[j, 0] * d2
        jac[2, j] = axes[j, 0] * d1 - axes[j, 1] * d0
        jac[3, j], jac[4, j], jac[5, j] = axes[j, 0], axes[j, 1], axes[j, 2]
    m = np.empty((3, 3))  # R_goal R_Tᵀ
    for a in range(3):
        error[a] = goal[a, 3] - tcp[a]
        for b in range(3):
            m[a, b] = goal[a, 0] * rt[b, 0] + goal[a, 1] * rt[b, 1] + goal[a, 2] * rt[b, 2]
    v0, v1, v2 = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    sine = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    cosine = 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0)
    angle = math.atan2(sine, cosine)
    if sine > 1e-9 or cosine > 0.0:
        scale = 0.5 * angle / sine if sine > 1e-300 else 0.5
        error[3], error[4], error[5] = scale * v0, scale * v1, scale * v2
    else:  # a half turn: the axis from the largest column of (R + I) / 2
        k = 0
        for c in range(1, 3):
            if m[c, c] > m[k, k]:
                k = c
        norm = 0.0
        for a in range(3):
            norm += (m[a, k] + (1.0 if a == k else 0.0)) ** 2
        norm = math.sqrt(norm)
        for a in range(3):
            error[3 + a] = angle * (m[a, k] + (1.0 if a == k else 0.0)) / norm
    total = 0.0
    for a in range(6):
        total += error[a] * error[a]
    return math.sqrt(total)


@compiled
def _newton_from_seeds(model, tool, goal, seeds, iterations, solutions, residuals):
    """Levenberg-Marquardt from each seed (k, 6) into ``solutions``: (JᵀJ + λ² I) dq = Jᵀ e with
    λ² = μ (|e|² + 1e-12) (Sugihara's damping scaled by μ, x10 on a rejected step, /10 on an
    accepted one); below |e| = 1e-6 plain Newton steps J dq = e while the error keeps falling.
    The final |error| into ``residuals`` (k)."""
    jac, error = np.empty((6, 6)), np.empty(6)
    trial_jac, trial_error = np.empty((6, 6)), np.empty(6)
    normal, rhs, step, trial = np.empty((6, 6)), np.empty(6), np.empty(6), np.empty(6)
    for s in range(seeds.shape[0]):
        q = solutions[s]
        q[:] = seeds[s]
        norm = _tcp_error(model, q, tool, goal, jac, error)
        mu = 1.0
        for _ in range(iterations):
            newton = norm < 1e-6
            lam2 = 0.0 if newton else mu * (norm * norm + 1e-12)
            for a in range(6):
                rhs[a] = error[a] if newton else 0.0
                for b in range(6):
                    normal[a, b] = jac[a, b] if newton else (lam2 if a == b else 0.0)
            if not newton:
                for a in range(6):
                    for k in range(6):
                        rhs[a] += jac[k, a] * error[k]
                    for b in range(6):
                        for k in range(6):
                            normal[a, b] += jac[k, a] * jac[k, b]
            if not _solve6(normal, rhs, step):
                break
            for a in range(6):
                trial[a] = q[a] + step[a]
            trial_norm = _tcp_error(model, trial, tool, goal, trial_jac, trial_error)
            if trial_norm < norm:
                q[:] = trial
                jac[:, :] = trial_jac
                error[:] = trial_error
                norm = trial_norm
                mu = max(mu * 0.1, 1e-6)
            elif newton or mu > 1e8:
                break  # converged as far as the arithmetic goes, or stuck
            else:
                mu *= 10.0
        residuals[s] = norm


@functools.lru_cache(maxsize=16)
def _seeds(lower: tuple, upper: tuple) -> np.ndarray:
    """IK_SEEDS scrambled Sobol points (fixed seed) in the joint box, each joint's range cut to
    one turn (-π, π] where wider (solutions are moved into the limits by whole turns)."""
    from scipy.stats import qmc

    low = np.maximum(np.array(lower), -np.pi)
    high = np.minimum(np.array(upper), np.pi)
    points = qmc.Sobol(d=NUM_JOINTS, scramble=True, seed=0).random(IK_SEEDS)
    seeds = low + points * (high - low)
    seeds.flags.writeable = False
    return seeds


def _into_limits(q: np.ndarray, lower: np.ndarray, upper: np.ndarray):
    """q wrapped to (-π, π], each joint then moved by whole turns into [lower, upper] (the
    representative nearest zero); None where a joint has none within its limits."""
    q = wrap_angle(q)
    for j in range(NUM_JOINTS):
        if not lower[j] - 1e-12 <= q[j] <= upper[j] + 1e-12:
            turns = np.arange(np.ceil((lower[j] - q[j]) / (2 * np.pi) - 1e-12),
                              np.floor((upper[j] - q[j]) / (2 * np.pi) + 1e-12) + 1)
            if turns.size == 0:
                return None
            q[j] += 2 * np.pi * turns[np.argmin(np.abs(q[j] + 2 * np.pi * turns))]
    return q


def chain_reach(model) -> float:
    """An upper bound [m] of the flange's distance from joint 1's origin: the sum of the fixed
    translations after joint 1 (the links a rotation of joint 1 and beyond can swing)."""
    return float(sum(np.linalg.norm(model[_TRANSFORMS + 12 * i + 9:_TRANSFORMS + 12 * i + 12])
                     for i in range(1, NUM_JOINTS + 1)))


def inverse_kinematics_all(model, pose, tool=FLANGE, lower=None, upper=None) -> np.ndarray:
    """Every joint solution q (k, 6) [rad] of the TCP pose ``pose`` = [x, y, z, φ_X, φ_Y, φ_Z]
    (base frame, m and Z-Y-X Euler angles in rad) for the packed chain ``model`` with TCP ``tool``
    (X_FT), within the joint limits ``lower``, ``upper`` [rad] (default ±2π).

    Numerical: Levenberg-Marquardt then Newton on the SE(3) error from :data:`IK_SEEDS`
    deterministic quasi-random seeds within the limits, polished to machine precision (pose error
    below :data:`IK_TOLERANCE`). Solutions are distinct modulo 2π (closer than
    :data:`IK_DISTINCT` rad are one), each wrapped to (-π, π] where that is within the limits,
    else moved into them by whole turns; sorted lexicographically. An arm with more solutions
    than the seeds find would miss some: the tests check the UR10e's eight.

    Raises:
        DrakeTrajError: a pose not six finite numbers (field ``pose``).
        UnreachablePoseError: no seed reaches the pose (the message gives the flange's distance
            from joint 1's origin and the arm's reach bound), or every solution is beyond the
            limits (naming the joint); its ``pose`` is the flange pose asked for.
        SingularConfigurationError: the pose is reached only at singular configurations.

    Singular solutions (measure below :data:`IK_SINGULAR_TOLERANCE`: a continuum, such as the
    UR10e's q4 + q6 at sin q5 = 0) are left out where regular ones exist (the UR closed form
    refuses such a pose; here the other branches' regular solutions are returned).
    """
    model = np.ascontiguousarray(model, dtype=float)
    pose = finite_array(pose, "pose", "m and rad", shape=(6,))
    tool = np.ascontiguousarray(tool, dtype=float)
    lower = np.full(NUM_JOINTS, -2 * np.pi) if lower is None else np.asarray(lower, dtype=float)
    upper = np.full(NUM_JOINTS, 2 * np.pi) if upper is None else np.asarray(upper, dtype=float)
    goal = np.eye(4)
    goal[:3, :3] = rotation_from_zyx_euler(pose[3:])
    goal[:3, 3] = pose[:3]
    seeds = _seeds(tuple(lower), tuple(upper))
    solutions, residuals = np.empty_like(seeds), np.empty(len(seeds))
    _newton_from_seeds(model, tool, goal, seeds, IK_ITERATIONS, solutions, residuals)
    found, beyond = [], None
    for q in solutions[residuals < IK_TOLERANCE]:
        inside = _into_limits(q, lower, upper)
        if inside is None:
            beyond = q
        elif not found or np.min(np.max(np.abs(wrap_angle(np.array(found) - inside)), axis=1)) >= IK_DISTINCT:
            found.append(inside)
    where = f"pose [x, y, z, phi_X, phi_Y, phi_Z] = {format_point(pose)} (m, rad)"
    if not found:
        flange_goal = goal @ np.linalg.inv(tool)
        if beyond is not None:
            j = int(np.argmax((wrap_angle(beyond) < lower) | (wrap_angle(beyond) > upper)))
            raise UnreachablePoseError(f"{where} is reached only beyond the joint limits: {joint_label(j)} at "
                                       f"{wrap_angle(beyond)[j]:.6g} rad, limits [{lower[j]:.6g}, {upper[j]:.6g}] "
                                       f"rad", pose=flange_goal)
        first = model[_TRANSFORMS + 9:_TRANSFORMS + 12]
        distance = float(np.linalg.norm(flange_goal[:3, 3] - first))
        raise UnreachablePoseError(f"{where} is out of reach: the flange would be {distance:.6g} m from joint 1's "
                                   f"origin, the arm reaches at most {chain_reach(model):.6g} m from it, and no "
                                   f"solution was found from {len(seeds)} starts", pose=flange_goal)
    found.sort(key=tuple)
    measures = [_measure(model, q, tool) for q in found]
    regular = [q for q, measure in zip(found, measures) if measure >= IK_SINGULAR_TOLERANCE]
    if not regular:
        raise SingularConfigurationError(f"{where} is reached only at singular configurations (singularity measure "
                                         f"{float(np.max(measures)):.2g} at best): the joint solution is not determined")
    return np.array(regular)


WARM_START_REACH = 0.5  # [rad], a warm-started IK solution this close to its start (every joint) keeps its branch


def inverse_kinematics_near(model, pose, start, tool=FLANGE, lower=None, upper=None):
    """The joint solution q (6,) [rad] of the TCP pose ``pose`` = [x, y, z, φ_X, φ_Y, φ_Z] (as
    :func:`inverse_kinematics_all`) that Levenberg-Marquardt then Newton reach from ``start``
    alone (a warm start: the previous point's solution on a path), on ``start``'s branch: None
    unless it converges (pose error below :data:`IK_TOLERANCE`) within :data:`WARM_START_REACH`
    of ``start`` in every joint, within the limits ``lower``, ``upper`` [rad] and regular
    (measure at least :data:`IK_SINGULAR_TOLERANCE`). The caller then falls back to the seeds
    (:func:`inverse_kinematics_all`)."""
    model = np.ascontiguousarray(model, dtype=float)
    tool = np.ascontiguousarray(tool, dtype=float)
    start = np.ascontiguousarray(start, dtype=float).reshape(1, NUM_JOINTS)
    goal = np.eye(4)
    goal[:3, :3] = rotation_from_zyx_euler(pose[3:])
    goal[:3, 3] = pose[:3]
    solution, residual = np.empty_like(start), np.empty(1)
    _newton_from_seeds(model, tool, goal, start, IK_ITERATIONS, solution, residual)
    q = solution[0]
    if not residual[0] < IK_TOLERANCE or np.max(np.abs(q - start[0])) > WARM_START_REACH:
        return None
    if (lower is not None and np.any(q < np.asarray(lower) - 1e-12)) or \
            (upper is not None and np.any(q > np.asarray(upper) + 1e-12)):
        return None
    if _measure(model, q, tool) < IK_SINGULAR_TOLERANCE:
        return None
    return q
