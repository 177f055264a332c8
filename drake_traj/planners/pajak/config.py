"""The Pająk 2024 planner's config: :class:`PajakConfig` (the scenario's ``planner`` entry, tag
``!PajakConfig``, and the law's parameters) and its checks. The paper's task is in
:mod:`.parameters`."""

from dataclasses import dataclass, field, replace
from typing import Optional

import numpy as np

from drake_traj.errors import Cause, DrakeTrajError, SingularConfigurationError
from drake_traj.robots import UR10E, Robot
from drake_traj.validation import flag, invalid, positive_vector, real_array, step_size

__all__ = ["PajakConfig", "TASK_JOINTS"]

TASK_JOINTS = 6  # the planner drives six joints, one per task coordinate [x, y, z, φ_X, φ_Y, φ_Z]


@dataclass
class PajakConfig:
    """The Pająk 2024 planner's task and settings (section "Model and task of the manipulator"):
    the scenario's ``planner: !PajakConfig`` entry and the law's parameters.

    Attributes:
        waypoints: (w, 6) task poses p_1..p_w [x, y, z, φ_X, φ_Y, φ_Z] [m, rad]; p_w is p_f.
        position_gain: Λ_P (scalar or 6 values) [1/s²], eq. 9.
        velocity_gain: Λ_V (scalar or 6 values) [1/s], eq. 9.
        velocity_limit: q̇_max = -q̇_min (scalar or 6) [rad/s], eq. 4; None (left out): the
            robot's joint-move speeds (:attr:`~drake_traj.robots.base.Robot.joint_move_limits`).
        acceleration_limit: q̈_max = -q̈_min (scalar or 6) [rad/s²], eq. 5; None: the robot's
            joint-move accelerations.
        vartheta: ϑ, penalty threshold on the normalised distance d (eq. 14), in (0, 0.5).
        rho: ρ, penalty strength (eq. 14) [rad²/s³], not given in the paper (ours: 0.03, docs/papers.md).
        accuracy: ε, the task is finished when the TCP is this close to p_w [m] (and its
            orientation within ``orientation_accuracy``).
        orientation_accuracy: the task is finished when the angle of R_wᵀ R between the tool's
            orientation R and p_w's R_w is below this [rad] (and the position within ε): the
            paper's |e| < ε read over all six components of e.
        neighbourhood: ϵ, radius of the blending ball around each waypoint [m] (eq. 19).
        limit_velocity: add the penalty perturbation Δq̈ (eq. 15-16); sims 2 and 3.
        limit_acceleration: scale the trajectory (eq. 17-18), c(0) = 0; sim 3.
        blend_waypoints: pass waypoints without stopping (eq. 19); False stops at each.
        smooth_penalty: improvement 1, penalty with zero slope at the threshold and a capped
            stiffness (kernel.PENALTY_STIFFNESS).
        continuous_switching: improvement 1, the waypoint switches when σ reaches 1 (literal:
            when the TCP leaves the ball).
        bounded_scaling: improvement 2, c in [0, 1], limits kept by braking when no c works.
        damped_inverse: improvement 3, damped least squares near a singular J.
        preserve_damping: improvement 4, no error component changes sign (overshoot) near the
            final goal, whatever c.
        continuous_orientation: improvement 6, each orientation component of the error on the
            branch (a multiple of 2π) nearest its value at the last update, so e is continuous
            where a component passes ±π (literal: wrapped to (-π, π], a jump of 2π there).
        scaling_rate: rate of eq. 18 [1/s] (1 in the paper).
        scaling_slew: improvement 1 (with ``bounded_scaling``): c changes by at most this per
            second [1/s]; where the limits would need c to fall faster, q̈ is clipped to them.
        jerk_budget: improvement 1 (with ``limit_acceleration`` and ``bounded_scaling``): the
            largest rate [rad/s³] at which each of these may change any q̈_i: c (its rate limit
            is lowered below ``scaling_slew``), the blend's σ moving the target (eq. 19) and the
            approach rate of improvement 4 falling.
        jerk_limit: improvement 1 (with ``limit_acceleration`` and ``bounded_scaling``): q̈_i
            changes by at most this [rad/s³] (0.08 rad/s² in 1 ms), the joint limits
            (eq. 4-5) excepted; where the law's own q̈ changes faster (near a singular J, where
            a = -J⁻¹J̇q̇ of eq. 17 grows faster than the scaling can follow), q̈ follows it at
            this rate.
        singularity_threshold: damped least squares below this :func:`drake_traj.robot.singularity_measure`.
        max_damping: damping λ of the damped least squares at a singular J.
        stop_speed: stop mode: TCP speed [m/s] below which a waypoint counts as reached.
        stall_time: no progress (remaining path shorter by 0.1 mm) for this long [s] raises
            PlanningError.
        blend_length: σ = path length through the ball / (blend_length · ϵ) (eq. 19 reading).
        update_period: period of the planner system's discrete update (eq. 18 anchor, waypoint
            switching) [s], at least 1e-5 s.

    Gains and limits are one number for every joint (task component) in a scenario file; from
    Python they may also be 6 values.
    """

    waypoints: list[list[float]] = field(default_factory=list)
    position_gain: float = 20.0
    velocity_gain: float = 9.392
    velocity_limit: Optional[float] = None  # (typing.Optional: the form pydrake's YAML reader takes)
    acceleration_limit: Optional[float] = None
    vartheta: float = 0.1
    rho: float = 0.03
    accuracy: float = 0.001
    orientation_accuracy: float = 0.001
    neighbourhood: float = 0.05
    limit_velocity: bool = True
    limit_acceleration: bool = True
    blend_waypoints: bool = True
    smooth_penalty: bool = True
    continuous_switching: bool = True
    bounded_scaling: bool = True
    damped_inverse: bool = True
    preserve_damping: bool = True
    continuous_orientation: bool = True
    scaling_rate: float = 1.0
    scaling_slew: float = 3.0
    jerk_budget: float = 40.0
    jerk_limit: float = 80.0
    singularity_threshold: float = 0.1
    max_damping: float = 0.2
    stop_speed: float = 0.01
    stall_time: float = 3.0
    blend_length: float = 1.25
    update_period: float = 0.001

    def validate(self, robot: Robot = UR10E) -> "PajakConfig":
        """Check every field; return a copy with arrays normalised ((w, 6) waypoints, (6,) gains
        and limits; None limits kept: the law takes the robot's). Raises ValueError naming the
        field. ``robot``: the robot it runs on; the checks do not depend on it (six task
        coordinates; :class:`~.law.PajakLaw` checks the robot, before this)."""
        n = TASK_JOINTS
        waypoints = real_array(self.waypoints, "waypoints", "m and rad, shape (w, 6)")
        if waypoints.ndim == 1 and waypoints.shape == (6,):
            waypoints = waypoints[None, :]
        if waypoints.ndim != 2 or waypoints.shape[1] != 6 or waypoints.shape[0] == 0:
            raise invalid("waypoints", f"waypoints must have shape (w, 6) with w >= 1, got shape {waypoints.shape}")
        if not np.all(np.isfinite(waypoints)):
            k = int(np.argwhere(~np.isfinite(waypoints))[0, 0])
            raise invalid("waypoints", f"waypoints[{k}] must be finite, got {waypoints[k].tolist()}", k)
        # No distance check here: a waypoint is out of reach only where inverse kinematics finds no
        # configuration for it (the law's reach check, with the robot's tool); UR's 1.3 m is the
        # brochure's round figure, and flange poses of in-range configurations lie up to 1.32 m
        # from the shoulder.
        if np.any(np.abs(np.cos(waypoints[:, 4])) < 1e-3):
            k = int(np.argmax(np.abs(np.cos(waypoints[:, 4])) < 1e-3))
            raise SingularConfigurationError(
                f"waypoints[{k}] phi_Y = {waypoints[k, 4]:.4f} rad is at +-pi/2: Z-Y-X Euler angles are "
                "singular (gimbal lock) there", field=("waypoints", k))
        values = {}
        for name in ("position_gain", "velocity_gain", "velocity_limit", "acceleration_limit"):
            value = getattr(self, name)
            is_default_limit = value is None and name.endswith("_limit")
            values[name] = None if is_default_limit else positive_vector(value, name, n)
        for name in (
            "rho", "accuracy", "orientation_accuracy", "neighbourhood", "scaling_rate", "scaling_slew", "jerk_budget",
            "jerk_limit", "singularity_threshold", "max_damping",
            "stop_speed", "stall_time", "blend_length", "update_period",
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise invalid(name, f"{name} must be a real number, got {value!r}")
            if not np.isfinite(value) or value <= 0:
                raise invalid(name, f"{name} must be finite and > 0, got {value}")
            values[name] = float(value)
        step_size(values["update_period"], "update_period")
        vartheta = self.vartheta
        if isinstance(vartheta, bool) or not isinstance(vartheta, (int, float, np.floating)) or not (
            0.0 < vartheta < 0.5
        ):
            raise invalid("vartheta", f"vartheta must be a number in (0, 0.5), got {vartheta!r}")
        if values["accuracy"] > values["neighbourhood"]:
            raise invalid("accuracy", f"accuracy ({values['accuracy']} m) must not be larger than neighbourhood "
                                      f"({values['neighbourhood']} m)")
        steps = np.linalg.norm(np.diff(waypoints[:, :3], axis=0), axis=1)
        if np.any(steps < values["neighbourhood"]):
            k = int(np.argmax(steps < values["neighbourhood"]))
            raise DrakeTrajError(
                f"waypoints[{k}] and waypoints[{k + 1}] are {steps[k]:.4f} m apart, closer than the "
                f"neighbourhood {values['neighbourhood']} m", field=("waypoints", k + 1), cause=Cause.INFEASIBLE)
        for name in (
            "limit_velocity", "limit_acceleration", "blend_waypoints", "smooth_penalty",
            "continuous_switching", "bounded_scaling", "damped_inverse", "preserve_damping", "continuous_orientation",
        ):
            flag(getattr(self, name), name)
        return replace(self, waypoints=waypoints, vartheta=float(vartheta), **values)
