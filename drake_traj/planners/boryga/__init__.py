"""Rectilinear path with a loop through the corner: geometry and time law (Boryga, Boryga).

Boryga (M. Boryga, "Trajectory Planning of an End-Effector for Path with Loop") moves the tool
from B to E through a sharp corner M without stopping there. The path is two straight segments,
B -> M and M -> E, joined by a loop through the corner:

    B --(7th-degree start-up)--> M --(v_max)--> T1 --(arc about O1, v_max)--> T2 --(v_max)--> M
      --(7th-degree braking)--> E

The tool passes M twice; the time between the two passes is the loop time. On B -> M the
acceleration is the first (start-up) half of the 7th-degree profile of eq. 1, so the tool leaves B
at rest and reaches M at v_max with zero acceleration (and zero jerk). M -> T1, the arc T1 -> T2 and
T2 -> M run at the constant speed v_max. On M -> E the acceleration is the second (braking) half of
the profile, so the tool stops at E with zero acceleration. The loop circle of radius R is centred
at O1 on the bisector of the angle BME, at distance Delta from M, and is tangent to the extensions
of BM and EM beyond M at T1 and T2 (section 2.2).

Equation numbers below are the paper's. The corrections in docs/papers.md are trusted over the OCR'd
text: the paper's p_BM of 4.46156e4 m/s^9 transposes digits (4.46516e4), its t_e = 0.815 s is a sum
of rounded parts (0.81368 s), its total path 0.152 m is 0.15217 m (the 0.036 m it gives "on the
loop" is the arc alone), its frame "zeta-eta-zeta" is xi-eta-zeta, and the start angle is beta_b in
eq. 11 and beta_p in section 3 (both pi - beta/2). The transformation T of eq. 12 is not given in
the paper; the construction of docs/papers.md is used: xi = (M - O1) / Delta, zeta = unit(a_hat x d_hat),
eta = zeta x xi, origin O1. With it the arc starts at T1 tangent to BM and ends at T2 heading
towards M along EM.

Geometric note (why no "loop crosses a segment" check exists): the loop circle is tangent to the
line BM at T1 and to the line EM at T2, so it lies on one side of each line and meets each line
only at its tangent point; T1 and T2 lie beyond M (M + l a_hat and M + l d_hat with l > 0), not on
the segments BM and ME. The path therefore touches itself only at M, for any B, M, E with a real
corner and any Delta > 0. What can fail is the input: coincident or collinear points (no corner, no
loop), non-positive or non-finite sizes and speeds, or a radius R and a distance Delta given
together that do not fit the corner (R must equal Delta sin(angle BME / 2)).

Modules: :mod:`.geometry` (section 2.2), :mod:`.path` (the profile and timing, eq. 1-14, and the path
in time), :mod:`.law` (the joint law on a robot), :mod:`.figures`, :mod:`.placements` (the paper's
loop in each workspace), :mod:`.config` (:class:`BorygaConfig` and its ``validate``) and
:mod:`.system` (the Drake system and ``make``). The math is plain numpy: tests call it directly and the
planner system is a thin shell around it. Positions are in the base frame xyz [m]; times in seconds.
"""

from drake_traj.planners.boryga.config import BorygaConfig
from drake_traj.planners.boryga.figures import loop_path_figure
from drake_traj.planners.boryga.geometry import LoopGeometry, loop_geometry
from drake_traj.planners.boryga.law import RobotLoopLaw, joint_speed_cap
from drake_traj.planners.boryga.path import (PHASES, LoopPath, LoopTiming, loop_timing, plan_loop_path,
                                             poly7_profile, poly7_timing)
from drake_traj.planners.boryga.placements import PAPER_LOOP, LoopPlacement, paper_loop_placement
from drake_traj.planners.boryga.system import BorygaLoopPlanner, make

__all__ = [
    "PAPER_LOOP", "PHASES", "BorygaConfig", "BorygaLoopPlanner", "LoopGeometry", "LoopPath", "LoopPlacement",
    "LoopTiming", "RobotLoopLaw", "joint_speed_cap", "loop_geometry", "loop_path_figure", "loop_timing", "make",
    "paper_loop_placement", "plan_loop_path", "poly7_profile", "poly7_timing",
]
