"""One compiled task-kinematics function for every 6-axis arm: the arm is data (``model``).

The Pająk 2024 law is compiled once and cached on disk (:mod:`drake_traj.compiled`); it calls
:func:`task_kinematics_into` with the arm's ``model`` array, so one compiled law serves every arm.
``model[0]`` says which form the rest of the array feeds:

- :data:`~drake_traj.robots.ur_closed_form.UR_CLOSED_FORM`: the UR e-Series closed form,
  [kind, d1, a2, a3, d4, d5, d6] (:func:`drake_traj.robots.ur_closed_form.kinematics_into`);
- :data:`~drake_traj.robots.chain_kinematics.CHAIN`: any serial chain of six revolute joints (standard or
  modified DH, a URDF/SDF read through MultibodyPlant), :meth:`~drake_traj.robots.chain.SerialChain.packed`
  (:func:`drake_traj.robots.chain_kinematics.chain_kinematics_into`).
"""

from __future__ import annotations

import math

import numpy as np

from drake_traj.compiled import compiled, sources_digest
from drake_traj.errors import SingularConfigurationError
from drake_traj.robots import chain_kinematics, task_space, ur_closed_form
from drake_traj.robots.base import FLANGE
from drake_traj.robots.chain_kinematics import CHAIN, chain_kinematics_into
from drake_traj.robots.ur_closed_form import UR_CLOSED_FORM
from drake_traj.robots.ur_closed_form import kinematics_into as ur_kinematics_into
from drake_traj.validation import finite_array, invalid

__all__ = ["SOURCES", "kinematics_many", "point_motion_rates", "task_kinematics", "task_kinematics_into"]

# The source files of the compiled code behind task_kinematics_into: it and its compiled callers
# (the Pająk kernel) close over their digest, numba's cache key (drake_traj.compiled).
SOURCES = (__file__, ur_closed_form.__file__, chain_kinematics.__file__, task_space.__file__)
_DEPENDENCIES = sources_digest(*SOURCES)


def _task_kinematics_into_with(dependencies):
    @compiled
    def task_kinematics_into(model, q, qd, tool, pose, jac, bias):
        """k(q), the analytic J and J̇q̇ of the TCP ``tool`` (X_FT, 4x4) of the arm ``model`` into
        ``pose`` (6), ``jac`` (6, 6) and ``bias`` (6); returns (cos φ_Y, singularity measure in
        [0, 1]). An unknown ``model[0]`` fills NaN (the callers treat a non-finite pose as a failure)."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        if model[0] == UR_CLOSED_FORM:
            return ur_kinematics_into(model, q, qd, tool, pose, jac, bias)
        if model[0] == CHAIN:
            return chain_kinematics_into(model, q, qd, tool, pose, jac, bias)
        pose[:] = math.nan
        jac[:, :] = math.nan
        bias[:] = math.nan
        return math.nan, math.nan

    return task_kinematics_into


task_kinematics_into = _task_kinematics_into_with(_DEPENDENCIES)

def _kinematics_many_with(dependencies):
    @compiled
    def kinematics_many(model, q, qd, tool, pose, jac, bias, cos_pitch, measure):
        """:func:`task_kinematics_into` for each row of q, q̇ (k, 6) into the rows of the outputs."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        for k in range(q.shape[0]):
            cos_pitch[k], measure[k] = task_kinematics_into(model, q[k], qd[k], tool, pose[k], jac[k], bias[k])

    return kinematics_many


kinematics_many = _kinematics_many_with(_DEPENDENCIES)


def task_kinematics(model, q, qd, tool=FLANGE):
    """(k(q), J(q), J̇(q, q̇) q̇, cos φ_Y, singularity measure) of the TCP ``tool`` (X_FT, 4x4;
    default the flange) of the arm ``model`` (:func:`task_kinematics_into`), vectorised over
    leading dimensions: q [rad], q̇ [rad/s] of shape (..., 6).

    Returns:
        pose (..., 6) [m, rad], J (..., 6, 6), bias (..., 6) [m/s², rad/s²], cos_pitch (...),
        measure (...); for one state, cos_pitch and measure are floats. No exception at gimbal
        lock: callers check ``cos_pitch``.
    """
    model, tool = np.ascontiguousarray(model, dtype=float), np.ascontiguousarray(tool, dtype=float)
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    if q.shape == (6,) and qd.shape == (6,):
        pose, jac, bias = np.empty(6), np.empty((6, 6)), np.empty(6)
        cos_pitch, measure = task_kinematics_into(model, q, qd, tool, pose, jac, bias)
        return pose, jac, bias, cos_pitch, measure
    shape = np.broadcast_shapes(q.shape, qd.shape)
    if shape[-1:] != (6,):
        raise ValueError(f"q and qd must have shape (..., 6), got {q.shape} and {qd.shape}")
    rows = np.ascontiguousarray(np.broadcast_to(q, shape).reshape(-1, 6))
    rates = np.ascontiguousarray(np.broadcast_to(qd, shape).reshape(-1, 6))
    count = rows.shape[0]
    pose, jac, bias = np.empty((count, 6)), np.empty((count, 6, 6)), np.empty((count, 6))
    cos_pitch, measure = np.empty(count), np.empty(count)
    kinematics_many(model, rows, rates, tool, pose, jac, bias, cos_pitch, measure)
    lead = shape[:-1]
    return (pose.reshape(lead + (6,)), jac.reshape(lead + (6, 6)), bias.reshape(lead + (6,)), cos_pitch.reshape(lead),
            measure.reshape(lead))


def point_motion_rates(model, tool, q, v, a) -> tuple[np.ndarray, np.ndarray]:
    """(q̇ [rad/s], q̈ [rad/s²]) that move the TCP ``tool`` (X_FT) of the arm ``model`` with
    velocity ``v`` [m/s] and acceleration ``a`` [m/s²] (base frame) at q [rad], its Z-Y-X Euler
    angles held: q̇ = J⁻¹ [v; 0], q̈ = J⁻¹ ([a; 0] - J̇q̇) with the analytic Jacobian
    (:func:`task_kinematics`). q (..., 6), v and a (..., 3), broadcast together; each result
    their shape (..., 6).

    Raises:
        ValueError: q, v or a not finite or of the wrong shape, named.
        SingularConfigurationError: φ_Y at ±π/2 (cos φ_Y < 1e-6, gimbal lock) at some q, named.
    """
    q, v, a = finite_array(q, "q", "rad"), finite_array(v, "v", "m/s"), finite_array(a, "a", "m/s^2")
    for name, value, width in (("q", q, 6), ("v", v, 3), ("a", a, 3)):
        if value.shape[-1:] != (width,):
            raise invalid(name, f"{name} must have shape (..., {width}), got {value.shape}")
    lead = np.broadcast_shapes(q.shape[:-1], v.shape[:-1], a.shape[:-1])
    q = np.broadcast_to(q, lead + (6,))
    _, jacobian, _, cos_pitch, _ = task_kinematics(model, q, np.zeros_like(q), tool)
    locked = np.flatnonzero(np.reshape(cos_pitch, -1) < 1e-6)
    if locked.size:
        at = np.reshape(q, (-1, 6))[locked[0]]
        raise SingularConfigurationError(f"Z-Y-X Euler angles are singular at q={np.round(at, 6).tolist()}: "
                                         "phi_Y is at +-pi/2 (gimbal lock), B(phi) has no inverse")
    zeros = np.zeros(lead + (3,))
    twist = np.concatenate([np.broadcast_to(v, lead + (3,)), zeros], axis=-1)
    qd = np.linalg.solve(jacobian, twist[..., None])[..., 0]
    bias = task_kinematics(model, q, qd, tool)[2]
    rate = np.concatenate([np.broadcast_to(a, lead + (3,)), zeros], axis=-1) - bias
    return qd, np.linalg.solve(jacobian, rate[..., None])[..., 0]
