"""The acceleration-level planning law of Pająk 2024 for Python callers: :class:`PajakLaw`.

The paper plans the joint trajectory of a 6-DOF arm by integrating a joint acceleration law:
the task-space error e = k(q) - p (eq. 6) is driven by e'' + Λ_V e' + Λ_P e = 0 (eq. 9), which
gives q̈ = -J⁻¹ (J̇q̇ + Λ_V J q̇ + Λ_P e) (eq. 13). Joint velocity limits are kept by an interior
penalty near the limits (eq. 14-16) and joint acceleration limits by a trajectory-scaling
coefficient c: q̈ = a + c b (eq. 17), c chosen from the violated limits (cases 1-4, a-c) and
relaxed back to 1 by eq. 18. Waypoints are passed without stopping by blending the target in a
ball around each waypoint (eq. 19), or the arm stops at each.

The law itself is compiled (:mod:`.kernel`, one implementation for every caller); this module
packs a :class:`~.config.PajakConfig` into the kernel's vectors and turns its status codes
into :class:`PlanningError`. A LeafSystem (continuous state [q; q̇], the discrete state of
:class:`~.kernel.Discrete`) calls :meth:`PajakLaw.acceleration` from its derivatives and
:meth:`PajakLaw.update` from a periodic update; :func:`~.integration.integrate` runs a whole task.

Corrections, readings and our improvements (each a flag of :class:`~.config.PajakConfig`,
default on; all off gives the paper's method as printed, with the corrections) are listed in
docs/papers.md (Pająk 2024) and at the functions of :mod:`.kernel` (and :mod:`.terms`,
:mod:`.limits`) that implement them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from drake_traj.errors import Cause, PlanningError, SingularConfigurationError, joint_label
from drake_traj.planners.pajak.kernel import (
    KINEMATICS,
    GIMBAL_MARGIN,
    MIN_COS_PITCH,
    VIABILITY_MARGIN,
    Discrete,
    Evaluation,
    Parameter,
    Status,
    evaluate_kernel,
)
from drake_traj.planners.pajak.config import TASK_JOINTS, PajakConfig
from drake_traj.planners.pajak.stepping import finished_kernel, update_kernel
from drake_traj.planners.pajak.terms import ORIENTATION_LENGTH
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import limit_or_default

__all__ = ["DISCRETE_NAMES", "PajakLaw"]


def _names(layout) -> tuple[str, ...]:
    """Names of the entries of a flat vector with the IntEnum ``layout`` (fields of more than one
    entry get a suffix: x_ref_0, x_ref_1, ...)."""
    members = sorted((m for m in layout if m.name != "SIZE"), key=int)
    names = []
    for member, following in zip(members, members[1:] + [layout.SIZE]):
        size = following - member
        names += [member.name.lower()] if size == 1 else [f"{member.name.lower()}_{k}" for k in range(size)]
    return tuple(names)


DISCRETE_NAMES = _names(Discrete)  # the discrete state's entries, in order
STALL_SCALING = 0.5  # a stall where the limits set c below this is one where a joint's limit held c low


class PajakLaw:
    """The planning law of Pająk 2024 for one task.

    State: continuous (q, q̇) and the discrete vector of layout :class:`~.kernel.Discrete` (the
    first three entries are [c, t0, c0] of the scaling contract; :data:`DISCRETE_NAMES`).

    Args:
        parameters: the task and the law's settings (validated here; ValueError names the field).
        robot: the robot, reached through its :meth:`~drake_traj.robots.Robot.task_kinematics`
            only: a 6-axis arm whose kinematics are data (``model``) for the one compiled
            kinematics function the law is bound to (:data:`~.kernel.KINEMATICS`); a robot
            without them is refused with a ValueError naming it. Its TCP
            (:meth:`~drake_traj.robots.Robot.with_tcp`) is the tool the waypoints place.
    """

    def __init__(self, parameters: PajakConfig, robot: Robot = UR10E):
        if not isinstance(parameters, PajakConfig):
            raise ValueError(f"parameters must be a PajakConfig, got {type(parameters).__name__}")
        refused = f"the Pająk planner runs on a 6-axis arm with task-space kinematics, not on {robot.name!r}"
        try:
            kinematics = robot.task_kinematics()
        except ValueError as error:
            raise ValueError(f"{refused}: {error}") from None
        if any(getattr(kinematics, name) is not getattr(KINEMATICS, name)
               for name in ("kinematics_into", "orientation_error", "wrapped")):
            raise ValueError(f"{refused}: its task kinematics are not the ones the compiled law is bound to")
        self.robot, self.kinematics = robot, kinematics
        self.tool = np.ascontiguousarray(kinematics.tool, dtype=float)  # X_FT, the kernels' ``tool``
        self.model = np.ascontiguousarray(kinematics.model, dtype=float)  # the arm, the kernels' ``model``
        p = parameters.validate()
        velocity, acceleration = robot.joint_move_limits  # where the task gives none
        p = replace(p, velocity_limit=limit_or_default(p.velocity_limit, velocity, "velocity_limit", TASK_JOINTS),
                    acceleration_limit=limit_or_default(p.acceleration_limit, acceleration, "acceleration_limit",
                                                        TASK_JOINTS))
        self.parameters = p
        self.waypoints = np.ascontiguousarray(p.waypoints)
        count = len(self.waypoints)
        # remaining path after p_i (position + weighted orientation), for the progress monitor
        steps = np.linalg.norm(np.diff(self.waypoints[:, :3], axis=0), axis=1) + ORIENTATION_LENGTH * np.linalg.norm(
            kinematics.wrap_angle(np.diff(self.waypoints[:, 3:], axis=0)), axis=1)
        self.remaining = np.append(np.cumsum(steps[::-1])[::-1], 0.0)
        v = np.zeros(Parameter.SIZE)

        def put(slot, value):
            value = np.atleast_1d(np.asarray(value, dtype=float))
            v[slot:slot + len(value)] = value

        put(Parameter.KP, p.position_gain)
        put(Parameter.KV, p.velocity_gain)
        put(Parameter.QD_MAX, p.velocity_limit)
        put(Parameter.QDD_MAX, p.acceleration_limit)
        # velocity-viability bound of the acceleration box (improvement 2, kernel.viability_bound):
        # slope K at the velocity limit (the linear bound K x would reach q̈_max at d = ϑ/4); with
        # the jerk budget J it reaches q̈_max at x = q̈_max (q̈_max + 2 J/K) / (2 J) from the limit
        gain = p.acceleration_limit / (0.25 * p.vartheta * 2.0 * p.velocity_limit)
        put(Parameter.VIABILITY_GAIN, gain)
        onset_gap = p.acceleration_limit * (p.acceleration_limit + 2.0 * p.jerk_budget / gain) / (2.0 * p.jerk_budget)
        put(Parameter.VIABILITY_ONSET, p.velocity_limit * (1.0 - VIABILITY_MARGIN) - onset_gap)
        # |q̇| above which the penalty of eq. 14 is active: d < ϑ  <=>  |q̇| > q̇_max (1 - 2ϑ)
        put(Parameter.PENALTY_ONSET, p.velocity_limit * (1.0 - 2.0 * p.vartheta))
        for slot, value in (
            (Parameter.VARTHETA, p.vartheta), (Parameter.RHO, p.rho), (Parameter.ACCURACY, p.accuracy),
            (Parameter.ORIENTATION_ACCURACY, p.orientation_accuracy), (Parameter.NEIGHBOURHOOD, p.neighbourhood),
            (Parameter.BLEND_DISTANCE, p.blend_length * p.neighbourhood), (Parameter.SCALING_RATE, p.scaling_rate),
            (Parameter.SCALING_SLEW, p.scaling_slew), (Parameter.JERK_BUDGET, p.jerk_budget),
            (Parameter.JERK_LIMIT, p.jerk_limit),
            (Parameter.SINGULARITY_THRESHOLD, p.singularity_threshold),
            (Parameter.MAX_DAMPING, p.max_damping),
            (Parameter.APPROACH_DELTA, 1e-4 * p.accuracy),  # improvement 4: keeps the approach rate finite at p_w
            (Parameter.STOP_SPEED, p.stop_speed), (Parameter.STALL_TIME, p.stall_time),
            (Parameter.NUM_WAYPOINTS, count),
            (Parameter.LIMIT_VELOCITY, p.limit_velocity), (Parameter.LIMIT_ACCELERATION, p.limit_acceleration),
            (Parameter.BLEND_WAYPOINTS, p.blend_waypoints), (Parameter.SMOOTH_PENALTY, p.smooth_penalty),
            (Parameter.CONTINUOUS_SWITCHING, p.continuous_switching), (Parameter.BOUNDED_SCALING, p.bounded_scaling),
            (Parameter.DAMPED_INVERSE, p.damped_inverse), (Parameter.PRESERVE_DAMPING, p.preserve_damping),
            (Parameter.CONTINUOUS_ORIENTATION, p.continuous_orientation),
            # improvement 6's orientation is continuous near the gimbal lock, but not through it:
            # "ours" stops GIMBAL_MARGIN from it (kernel.GIMBAL_MARGIN), the paper's method at 1e-6
            (Parameter.MIN_COS_PITCH, GIMBAL_MARGIN if p.continuous_orientation else MIN_COS_PITCH),
        ):
            v[slot] = float(value)
        self.vector = v
        self.qd_max = v[Parameter.QD_MAX:Parameter.QD_MAX + 6].copy()
        self.qdd_max = v[Parameter.QDD_MAX:Parameter.QDD_MAX + 6].copy()
        self._out = np.zeros(Evaluation.SIZE)

    # --- discrete state ------------------------------------------------------------------------
    def initial_discrete(self) -> np.ndarray:
        """Discrete state at t = 0: c(0) = 0 with the anchor (t0, c0) = (0, 0) when the
        acceleration is limited (eq. 18, smooth start), c = 1 otherwise; waypoint 0; the TCP
        may already be inside the first ball (checked at the first update)."""
        d = np.zeros(Discrete.SIZE)
        c = 0.0 if self.parameters.limit_acceleration else 1.0
        d[Discrete.C] = d[Discrete.C0] = c
        d[Discrete.GOAL] = 1.0
        d[Discrete.BEST] = np.inf
        d[Discrete.HELD_BY] = -1.0  # no limit has set c yet
        return d

    # --- evaluation ----------------------------------------------------------------------------
    @staticmethod
    def _state(q, qd, discrete) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, q̇, discrete) as float arrays of shapes (6,), (6,), (Discrete.SIZE,); ValueError
        otherwise."""
        q, qd, discrete = (np.asarray(v, dtype=float) for v in (q, qd, discrete))
        if q.shape != (6,) or qd.shape != (6,) or discrete.shape != (Discrete.SIZE,):
            raise ValueError(f"q, qd and discrete must have shapes (6,), (6,) and ({Discrete.SIZE},), "
                             f"got {q.shape}, {qd.shape} and {discrete.shape}")
        return q, qd, discrete

    def _evaluate(self, t, q, qd, discrete) -> np.ndarray:
        evaluate_kernel(float(t), *self._state(q, qd, discrete), self.vector, self.model, self.tool, self.waypoints, self._out)
        return self._out

    def acceleration(self, t: float, q, qd, discrete) -> tuple[np.ndarray, float]:
        """(q̈ [rad/s²], c) at time t for the state (q, q̇) and the discrete state.

        q̈ is eq. 17 with c = min(eq. 18 relaxation from the anchor, the admissible ĉ for this
        state), evaluated here on every call, so the acceleration limits hold at every
        evaluation (not only at updates) and q̈ is continuous in t between updates.

        Raises:
            PlanningError: at the Euler angles' gimbal lock (cos φ_Y below 1e-3 with improvement 6,
                1e-6 without) or a non-finite q̈.
        """
        out = self._evaluate(t, q, qd, discrete)
        qdd = out[Evaluation.QDD:Evaluation.QDD + 6]
        locked = out[Evaluation.COS_PITCH] < self.vector[Parameter.MIN_COS_PITCH]
        if locked or not np.all(np.isfinite(qdd)):
            raise self.failure(Status.SINGULAR if locked else Status.NON_FINITE,
                               t, q, discrete, out)
        return qdd.copy(), float(out[Evaluation.C])

    def evaluate(self, t: float, q, qd, discrete) -> dict:
        """Everything the law computes at (t, q, q̇, discrete), as a dict (layout
        :class:`~.kernel.Evaluation`): qdd, c, c_relaxed, saturated (the limits overrule the law),
        violation (of the box by a alone), brake (weight of the fallback braking), sigma, measure
        (singularity), cos_pitch, pose, target."""
        out = self._evaluate(t, q, qd, discrete)
        return {
            "qdd": out[Evaluation.QDD:Evaluation.QDD + 6].copy(), "c": float(out[Evaluation.C]),
            "c_relaxed": float(out[Evaluation.C_RELAXED]), "saturated": bool(out[Evaluation.SATURATED]),
            "violation": float(out[Evaluation.VIOLATION]), "brake": float(out[Evaluation.BRAKE]),
            "sigma": float(out[Evaluation.SIGMA]), "measure": float(out[Evaluation.MEASURE]),
            "cos_pitch": float(out[Evaluation.COS_PITCH]), "pose": out[Evaluation.POSE:Evaluation.POSE + 6].copy(),
            "target": out[Evaluation.TARGET:Evaluation.TARGET + 6].copy(),
        }

    # --- discrete update -----------------------------------------------------------------------
    def update(self, t: float, q, qd, discrete, goal: float = 1.0) -> np.ndarray:
        """New discrete state at time t (call periodically, e.g. every integration step).

        Records the eq. 18 anchor (t0, c0) = (t, c) when the limits set c; switches waypoints
        (eq. 19 blending, or stop-and-go with c restarting from 0 when the acceleration is
        limited); tracks progress. ``goal`` in [0, 1] is the value c relaxes to (eq. 18: 1; the
        speed override): when it changes, the anchor becomes (t, c) with the new goal, so c
        stays continuous and approaches the goal at the rate of eq. 18.

        Raises:
            PlanningError: no progress for ``stall_time`` s, gimbal lock, or non-finite values.
        """
        q, qd, discrete = self._state(q, qd, discrete)
        updated = discrete.copy()
        status = update_kernel(float(t), q, qd, updated, self.vector, self.model, self.tool, self.waypoints, self.remaining,
                               self._out)
        if status < 0:
            raise self.failure(status, t, q, updated, self._out)
        if self.parameters.limit_acceleration and goal != updated[Discrete.GOAL]:
            updated[Discrete.T0] = t
            updated[Discrete.C0] = updated[Discrete.C]
            updated[Discrete.GOAL] = goal
        return updated

    def reach_failure(self, q0) -> PlanningError | None:
        """The :class:`PlanningError` (cause UNREACHABLE, time 0, field ``("waypoints", k)``) for the first waypoint whose
        TCP pose no IK branch of the UR10e reaches, naming it and the reason; None when every
        waypoint is reachable (a wrist-singular pose counts as reachable)."""
        for k, pose in enumerate(self.waypoints):
            try:
                self.kinematics.inverse_kinematics_all(pose)
            except SingularConfigurationError:
                continue
            except ValueError as exc:
                failure = PlanningError(f"waypoint {k} cannot be reached: {exc}", time=0.0,
                                        configuration=np.array(q0, dtype=float), cause=Cause.UNREACHABLE,
                                        field=("waypoints", k))
                failure.__cause__ = exc  # raised later, by the caller: the IK's error stays behind it
                return failure
        return None

    def finished(self, q, qd, discrete) -> bool:
        """True once the TCP is within ε of the final waypoint p_w and p_w is the active target."""
        return bool(finished_kernel(np.asarray(q, dtype=float), np.asarray(discrete, dtype=float), self.vector,
                                    self.model, self.tool, self.waypoints))

    def failure(self, status: int, t: float, q, discrete, out) -> PlanningError:
        """The :class:`PlanningError` for a failure ``status`` of the kernel at time t, from the
        discrete state and the evaluation ``out`` there."""
        status = Status(status)
        q = np.array(q, dtype=float)
        if status == Status.SINGULAR:
            margin = np.degrees(np.arcsin(self.vector[Parameter.MIN_COS_PITCH]))
            waypoint = int(discrete[Discrete.WAYPOINT])
            message = (f"the Euler angles' gimbal lock: φ_Y within {margin:.2g}° of ±90° on the way to waypoint "
                       f"{waypoint} (phi_Y = {out[Evaluation.POSE + 4]:.6f} rad, cos phi_Y = "
                       f"{out[Evaluation.COS_PITCH]:.2g}): the Z-Y-X Euler angles are singular there, the analytic "
                       "Jacobian has no inverse")
            cause, field = Cause.SINGULAR, ("waypoints", waypoint)
        elif status == Status.NON_FINITE:
            message = (f"non-finite state or acceleration {out[Evaluation.QDD:Evaluation.QDD + 6].tolist()} "
                       f"(singularity measure {out[Evaluation.MEASURE]:.2e})")
            cause, field = Cause.NON_FINITE, ()
        elif status == Status.STALL:
            why, field = self.stall_cause(q, discrete, out)
            message = (
                f"no progress towards waypoint {int(discrete[Discrete.WAYPOINT])} for "
                f"{self.parameters.stall_time:.1f} s {why}: remaining path {out[Evaluation.REMAINING]:.4f} m, TCP "
                f"{np.round(out[Evaluation.POSE:Evaluation.POSE + 3], 4).tolist()}, c = {out[Evaluation.C]:.3g}, "
                f"singularity measure {out[Evaluation.MEASURE]:.3g}"
            )
            cause = Cause.STALL
        else:
            raise ValueError(f"status {status!r} is not a failure")
        return PlanningError(message, time=float(t), configuration=q, cause=cause, field=field)

    def stall_cause(self, q, discrete, out) -> tuple[str, tuple]:
        """(why, field) of a stall at q with the discrete state and the evaluation ``out`` there:

        - near a singular configuration (singularity measure below ``singularity_threshold``):
          which one (the elbow, wrist or shoulder factor of det J, ``TaskKinematics.singularity_factors``),
          field ``("waypoints", i)``, the waypoint the arm cannot reach from there;
        - near the Euler angles' gimbal lock (cos φ_Y below 0.05): field ``("waypoints", i)``;
        - c held low: set below ``STALL_SCALING`` by the limits since the last progress (the
          joint whose limit set it, recorded with eq. 18's anchor), or below ``STALL_SCALING`` or
          eq. 18's value now (the joint whose limit bounds c lowest, :func:`~.limits.holding_joint`):
          its acceleration limit or the viability bound of its velocity limit, field ``("acceleration_limit",)`` or ``("velocity_limit",)``;
        - otherwise: the law's feedback stops short, c not held low and J regular, field ``("waypoints", i)``.
        """
        waypoint = ("waypoints", int(discrete[Discrete.WAYPOINT]))
        if out[Evaluation.MEASURE] < self.parameters.singularity_threshold:
            factors = self.kinematics.singularity_factors(q)
            name = min(factors, key=lambda key: factors[key][0])
            factor, meaning = factors[name]
            return f"near a singular configuration, the {name} singularity ({meaning}: factor {factor:.3g})", waypoint
        if out[Evaluation.COS_PITCH] < 0.05:
            return (f"near the gimbal lock of the Z-Y-X Euler angles (cos phi_Y = {out[Evaluation.COS_PITCH]:.3g})",
                    waypoint)
        c = out[Evaluation.C]
        # the joint whose limit set c at the last anchor of eq. 18, where that was since the last progress
        # and set c low (c relaxes from there at eq. 18's rate); else the one that bounds c now
        joint, by_velocity = int(discrete[Discrete.HELD_BY]), discrete[Discrete.HELD_BY_VELOCITY] > 0.5
        held = joint >= 0 and discrete[Discrete.C0] < STALL_SCALING and discrete[Discrete.T0] > discrete[Discrete.T_BEST]
        if not held:
            joint, by_velocity = int(out[Evaluation.HOLDING]), out[Evaluation.HOLDING_VELOCITY] > 0.5
            held = joint >= 0 and (c < STALL_SCALING or c < out[Evaluation.C_RELAXED] - 1e-3)
        if held:
            names = self.robot.joint_names
            if by_velocity:
                return (f"with c held low by {joint_label(joint, names)}'s velocity limit "
                        f"({self.qd_max[joint]:.3g} rad/s, its acceleration box narrowed near it)"), ("velocity_limit",)
            return (f"with c held low by {joint_label(joint, names)}'s acceleration limit "
                    f"({self.qdd_max[joint]:.3g} rad/s^2)"), ("acceleration_limit",)
        return "with c not held by a limit and J regular (the feedback stops short)", waypoint

    def tcp_positions(self) -> np.ndarray:
        """Waypoint positions [m], (w, 3), for plots."""
        return self.waypoints[:, :3].copy()
