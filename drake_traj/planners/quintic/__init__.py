"""Synchronised quintic point-to-point planner (Benotsmane et al., Benotsmane).

Benotsmane et al. (Benotsmane, Kacemi, Benachenhou: "Calculation methodology for trajectory planning of a
6 axis manipulator arm") moves all joints from q^i to q^f along the same fifth-degree time law
r(t) (eq. 6), so every joint leaves and arrives at the same time. The duration t_f is the minimum
time of the constraining joint (eq. 8, 9): the slowest joint touches its velocity limit K_v or its
acceleration limit K_a, every other joint stays below its own. A sequence of goals is a chain of
such moves with a stop (zero velocity and acceleration) at every goal.

Equation numbers below are the paper's. Its numbering is repeated: "(8)" is both the peak
acceleration and t_f = max_j t_fj; comments say which one is meant. Eq. 9 as printed (K_a^2 under
the root) is wrong; docs/papers.md gives the corrected form used here,
t_fj = max(15|D_j| / (8 K_vj), sqrt(10 |D_j| / (sqrt(3) K_aj))), and D_j is the displacement
q^f_j - q^i_j [rad], not a duration.

Modules: :mod:`.profile` (the law r(s) and the timing, eq. 6-9), :mod:`.law` (segments, the
chained :class:`QuinticLaw` and its planning), :mod:`.config` (:class:`QuinticConfig` and its
``validate``) and :mod:`.system` (the Drake system and ``make``). The math is plain numpy: tests
call it directly and the planner system is a thin shell around it.
"""

from drake_traj.planners.quintic.config import QuinticConfig
from drake_traj.planners.quintic.law import QuinticLaw, QuinticSegment, plan_synchronized_quintic
from drake_traj.planners.quintic.profile import (
    joint_minimum_times,
    peak_acceleration,
    peak_velocity,
    quintic_profile,
    synchronized_duration,
)
from drake_traj.planners.quintic.system import QuinticPtpPlanner, make

__all__ = [
    "QuinticConfig", "QuinticLaw", "QuinticPtpPlanner", "QuinticSegment", "joint_minimum_times", "make",
    "peak_acceleration", "peak_velocity", "plan_synchronized_quintic", "quintic_profile", "synchronized_duration",
]
