"""Li et al. 2019 end to end: Cartesian stage, IK, re-timing, quintic B-spline, and our repairs.

The stages (docs/papers.md, "Li et al. 2019"; the repairs and their measurements in
docs/li_efficiency.md):

1. the Cartesian stage on the tool path (eq. 1-13, Fig. 2: :mod:`.cartesian`);
2. inverse kinematics of the path points, timed by the Cartesian stage;
3. the re-timing of eq. 14 (:func:`.joint.retime_joint_samples`, never faster than the Cartesian
   stage): the shortest time each interval may take;
4. the quintic B-spline of eq. 15-22 through the samples at the Cartesian times, then two smooth
   time warps (:func:`.repair.smooth_time_warp`), with one log-stretch slope for both:

   - the joint repair: every interval at least as long as eq. 14 makes it, and the joint limits at
     the exact polynomial peaks of every knot interval;
   - the tool repair: also the tool limits through forward kinematics (:func:`.repair.check_tool_limits`).

   Eq. 14's intervals enter as a requirement of the warp, not as knot times: taken as they are,
   single longer intervals make the interpolating spline ring (on the 4-DOF robot the tool then
   peaks at 7.6 times its acceleration limit and joint 3 at 2.0 times its own, where the spline at
   the Cartesian times keeps every joint limit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drake_traj.planners.li.cartesian import CartesianPlan, plan_cartesian_path
from drake_traj.planners.li.joint import JointSplineLaw, LimitReport, check_limits, retime_joint_samples
from drake_traj.planners.li.repair import (
    WARP_BUDGET,
    ToolLimitReport,
    WarpReport,
    check_tool_limits,
    joint_stretch,
    smooth_time_warp,
    warp_log_steps,
)

__all__ = ["LiPlan", "plan_li_path"]


@dataclass(frozen=True)
class LiPlan:
    """All stages of one Li et al. 2019 plan.

    Attributes:
        cartesian: the Cartesian stage (look-ahead and ACC/DEC on the tool path).
        q: the joint samples at the path points [rad], shape (N, n).
        retimed_times: the knot times of eq. 14 (never faster than the Cartesian stage) [s], (N,).
        joint_repair: the warp that keeps eq. 14's intervals and the joint limits.
        tool_repair: the warp that then also keeps the tool limits; its times are the law's.
        law: the executed joint spline.
        joint_check, tool_check: the final checks of ``law`` (both ``ok``).
    """

    cartesian: CartesianPlan
    q: np.ndarray
    retimed_times: np.ndarray
    joint_repair: WarpReport
    tool_repair: WarpReport
    law: JointSplineLaw
    joint_check: LimitReport
    tool_check: ToolLimitReport

    @property
    def stage_durations(self) -> dict[str, float]:
        """Length of the motion after each stage [s]."""
        return {
            "cartesian": self.cartesian.duration,
            "retimed": float(self.retimed_times[-1] - self.retimed_times[0]),
            "joint_repair": self.joint_repair.final_duration,
            "executed": self.law.duration,
        }


def plan_li_path(points, ik, tool_motion, velocity_limit, acceleration_limit, tool_velocity_limit,
                 tool_acceleration_limit, *, warp_budget: float = WARP_BUDGET) -> LiPlan:
    """Li et al. 2019 end to end, with the joint and the tool limits kept (module docstring).

    Args:
        points: the tool path [m], shape (N, 3).
        ik: ``ik(points) -> q (N, n)``, the robot's inverse kinematics of the path points.
        tool_motion: ``tool_motion(q, qd, qdd) -> (v, a)``, the robot's FK rates.
        velocity_limit, acceleration_limit: per joint [rad/s, rad/s^2].
        tool_velocity_limit, tool_acceleration_limit: Table 4's tool limits [m/s, m/s^2].
        warp_budget: share of every acceleration limit the warps themselves may use
            (:func:`.repair.warp_log_steps`).

    Returns:
        :class:`LiPlan`; ``plan.law`` keeps every limit at every instant (joints: exact
        polynomial peaks; tool: refined peaks per knot interval).

    Raises:
        ValueError: bad limits or points (named), a point out of reach (from ``ik``).
    """
    cartesian = plan_cartesian_path(points, tool_velocity_limit, tool_acceleration_limit)
    q = np.asarray(ik(cartesian.points), dtype=float)
    times = cartesian.segment_times
    retimed = retime_joint_samples(times, q, velocity_limit, acceleration_limit)
    # Most intervals keep their Cartesian duration; 1e-9 below it so that the round-off of the
    # warped knot times (cumulative sums, ~1e-13 relative) never reads as a broken requirement.
    min_durations = np.diff(retimed) * (1.0 - 1e-9)

    def check_tool(law):
        return check_tool_limits(law, tool_motion, tool_velocity_limit, tool_acceleration_limit)

    def joint_needs(law):
        eq14 = min_durations / np.diff(law.knot_times)
        return np.maximum(eq14, joint_stretch(check_limits(law, velocity_limit, acceleration_limit)))

    def all_needs(law):
        return np.maximum(joint_needs(law), check_tool(law).interval_stretch)

    # The log-stretch slope from the unwarped spline's speeds: the warp may add at most
    # warp_budget times each joint's and the tool's acceleration limit.
    base = JointSplineLaw(times, q)
    joints = check_limits(base, velocity_limit, acceleration_limit)
    tool = check_tool(base)
    rate = np.maximum(np.max(joints.interval_velocity / joints.acceleration_limit, axis=1),
                      tool.interval_speed / tool.acceleration_limit)
    steps = warp_log_steps(np.diff(times), rate, warp_budget)
    _, joint_repair = smooth_time_warp(times, q, joint_needs, steps)
    law, tool_repair = smooth_time_warp(times, q, all_needs, steps, initial_log_stretch=joint_repair.log_stretch)
    joint_check = check_limits(law, velocity_limit, acceleration_limit)
    tool_check = check_tool(law)
    return LiPlan(cartesian, q, retimed, joint_repair, tool_repair, law, joint_check, tool_check)
