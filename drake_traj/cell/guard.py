"""Every motion that runs is the motion that was checked: the station's guard.

A station (:func:`~drake_traj.station.add_station`) gives its planner a :class:`MotionGuard`: the
robot, the cell, the bodies added by ``before_finalize`` and the fingerprint of the station
plant's collision scene (:func:`~drake_traj.cell.clearance.scene_fingerprint`). Before the motion
starts, by :func:`~drake_traj.station.run_station` or by the planner's initialization event in
one's own ``Simulator``, the guard makes sure the planner's plan was accepted by the cell check
against that very scene (:meth:`CellChecker.check_planner
<drake_traj.cell.clearance.CellChecker.check_planner>` records the fingerprints it checked on the
planner), and checks it there where it was not: a motion that would hit the arm itself, its
tool or its cell is refused before it starts, whatever route started it. Only an explicit
``check_motion=False`` (``simulate(..., preflight=False)``) runs a plan unchecked.

While the motion runs, :class:`ClearanceWatch` follows the measured joint positions the station
logs (every plant step at the default log period) and fails the run when the measured motion
comes closer than half the clearance to anything, between samples included (the bound below).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drake_traj.cell.cell import Cell
from drake_traj.cell.clearance import CellChecker
from drake_traj.cell.reach import TRAVEL_MARGIN
from drake_traj.errors import Cause, Failure, PlanningError
from drake_traj.robots import Robot

__all__ = ["ClearanceWatch", "MotionGuard", "UncheckedMotionError"]

SPAN_TRAVEL = 0.02
"""[m] the longest span of logged samples one pair of queries covers, as the bound on two
bodies' relative travel: its radius is the limit plus this at most."""

MAX_SPLITS = 8
"""Halvings of one logged step at most where the bound cannot decide: the measured motion is
then within the limit less 1/256 of that step's travel bound (0.01 mm at 3 m/s)."""


class UncheckedMotionError(PlanningError):
    """The station cannot check the motion it was asked to run (its collision scene cannot be
    rebuilt for the check); the motion is refused."""


@dataclass
class MotionGuard:
    """What a station's motion is checked against (module docstring).

    Args:
        robot: the robot, as the station added it (its tool's geometry included by ``cell``).
        cell: the station's cell and tool.
        directory: where ``cell.directives``' relative files are read from.
        before_finalize: the station's ``before_finalize(plant, scene_graph)``, or None.
        fingerprint: the station plant's collision scene (:func:`~drake_traj.cell.clearance.scene_fingerprint`).
        check_motion: False only where the user asked for an unchecked run.
        unprotected_links: the robot's links without collision shapes, which the robot says may run
            unprotected (the cell check refuses any other: :func:`~drake_traj.cell.clearance.refuse_unprotected_links`).
        unchecked_pairs: the pairs of the robot's links the checks leave out
            (:class:`~drake_traj.robots.UncheckedPair`: :func:`~drake_traj.robots.exclude_self_contact`).
        preflight: ``preflight(planner, horizon)``, the scenario's preflight and cell check where
            the station was made from a scenario (a refusal then located in its file:
            :func:`drake_traj.scenario.preflight`), or None.
    """

    robot: Robot
    cell: Cell
    directory: object
    before_finalize: object
    fingerprint: str
    check_motion: bool = True
    preflight: object = None
    unprotected_links: tuple = ()  # the robot's links without collision shapes (said to run unprotected)
    unchecked_pairs: tuple = ()  # the pairs of the robot's links the checks leave out (UncheckedPair)
    _checker: CellChecker | None = field(default=None, repr=False)

    def checker(self) -> CellChecker:
        """A :class:`CellChecker` of the station's own scene (made once; its fingerprint equal to
        the station's, else :class:`UncheckedMotionError`)."""
        if self._checker is None:
            checker = CellChecker(self.robot, self.cell, self.directory, before_finalize=self.before_finalize)
            if checker.fingerprint != self.fingerprint:
                raise UncheckedMotionError(
                    "the station's collision scene could not be built again for the cell check (before_finalize adds "
                    "other bodies, shapes or filters at each call): the motion cannot be checked and is refused; make "
                    "before_finalize add the same bodies to any plant it is given", cause=Cause.COLLISION)
            self._checker = checker
        return self._checker

    def ensure_checked(self, planner, horizon: float) -> None:
        """Raise the refusal (a :class:`~drake_traj.errors.PlanningError`: a collision, a joint
        range, the task itself) unless ``planner``'s plan was accepted in the station's scene;
        check it there now where it was not (the preflight up to ``horizon`` [s], then the
        cell check). Nothing to do for an explicitly unchecked station."""
        if not self.check_motion or self.fingerprint in planner.checked_scenes:
            return
        if self.preflight is not None:  # the scenario's: its errors located in the scenario's file
            self.preflight(planner, horizon)
            if self.fingerprint in planner.checked_scenes:
                return
        planner.preflight(horizon)
        self.checker().check_planner(planner)

    def watch(self, logger, root_context, num_joints: int) -> "ClearanceWatch":
        """The :class:`ClearanceWatch` of the station's measured-state ``logger``."""
        return ClearanceWatch(self.checker(), logger, root_context, num_joints, checked=self.check_motion)


class ClearanceWatch:
    """Fails a run whose measured motion comes closer than half the clearance to anything.

    Fed the measured joint positions q_k the station logs at t_k (every plant step at the
    default log period), it bounds the distance between every two bodies along the whole
    measured motion, between samples included. Over a span of samples no point of the arm moves
    more than δ = 1.1 Σ_k Σ_j R_j |Δq_j,k| (R_j the cell check's joint reach bounds, 1.1 its
    TRAVEL_MARGIN), so two bodies come at most 2δ closer. SceneGraph's signed distances are queried at
    the span's ends out to limit + 2δ: a pair found at neither end stays beyond the limit inside,
    and a pair found at one end (d0, d1, the query's radius where it was not found) is no closer
    than (d0 + d1 - 2δ) / 2; where that does not decide, the span is halved at its middle sample
    (a single step at its interpolated middle), up to :data:`MAX_SPLITS` times. Spans are as long
    as :data:`SPAN_TRAVEL` allows and end at least at each call's last sample, so a query
    (17 µs on the UR10e's cell, whatever its radius) falls every few samples of a fast motion.

    Args:
        checker: the station's scene (:meth:`MotionGuard.checker`).
        logger: the station's ``measured_logger`` (its log [q; q̇] per sample).
        root_context: the simulator's root context (the log lives there).
        num_joints: n, the joints of q in the log's first n rows.
        checked: the motion was checked before it started (a failure then says the arm left it).
    """

    def __init__(self, checker: CellChecker, logger, root_context, num_joints: int, *, checked: bool = True):
        self.checker = checker
        self.limit = 0.5 * checker.clearance  # [m]
        self._travel = 2 * TRAVEL_MARGIN * checker.reach  # [m/rad] two bodies' relative travel per |Δq|
        self._log = logger.FindLog(root_context)
        self._n = num_joints
        self._last = None  # (index, (t, q, {pair: distance}, radius)) of the last queried sample
        self.queries = 0  # distance queries so far
        self._checked = checked

    def _near(self, t: float, q, within: float) -> tuple[tuple, Failure | None]:
        """((t, q, {pair of geometries: distance [m]} closer than ``within``, ``within``), the
        failure where a pair is closer than the limit)."""
        self.queries += 1
        pairs = self.checker.pose_query(q).ComputeSignedDistancePairwiseClosestPoints(within)
        near = {(pair.id_A, pair.id_B): pair.distance for pair in pairs}
        if near and min(near.values()) < self.limit:
            contact = self.checker.contacts(q, within=self.limit)[0]
            return (), self._failure(t, q, contact)
        return (t, q, near, within), None

    def _span(self, t, q, cumulative, i0: int, i1: int, start, end, depth=0) -> Failure | None:
        """Inside the samples i0..i1 (``start``, ``end`` their queries, :meth:`_near`;
        ``cumulative`` the travel bound [m] from the window's first sample): None where no pair
        comes closer than the limit."""
        (_, _, near0, within0), (_, _, near1, within1) = start, end
        reach = cumulative[i1] - cumulative[i0]
        pairs = {*near0, *near1}
        if not pairs or depth >= MAX_SPLITS:
            return None
        if min(near0.get(pair, within0) + near1.get(pair, within1) for pair in pairs) - reach >= 2 * self.limit:
            return None
        if i1 - i0 > 1:  # split at the middle sample
            m = (i0 + i1) // 2
            within = self.limit + max(cumulative[m] - cumulative[i0], cumulative[i1] - cumulative[m])
            middle, failure = self._near(t[m], q[m], within)
            return failure or self._span(t, q, cumulative, i0, m, start, middle, depth + 1) or \
                self._span(t, q, cumulative, m, i1, middle, end, depth + 1)
        # one step: halve it, positions interpolated
        tm, qm = 0.5 * (t[i0] + t[i1]), 0.5 * (q[i0] + q[i1])
        times, positions = np.array([t[i0], tm, t[i1]]), np.array([q[i0], qm, q[i1]])
        halves = cumulative[i0] + np.array([0.0, 0.5, 1.0]) * reach
        middle, failure = self._near(tm, qm, self.limit + 0.5 * reach)
        return failure or self._span(times, positions, halves, 0, 1, start, middle, depth + 1) or \
            self._span(times, positions, halves, 1, 2, middle, end, depth + 1)

    def feed(self) -> Failure | None:
        """Watch the samples logged since the last call: the :class:`Failure` of the first place
        where the measured motion came closer than the limit, else None."""
        data, times = self._log.data(), self._log.sample_times()
        count = len(times)
        if self._last is None:
            if not count:
                return None
            first, failure = self._near(float(times[0]), data[: self._n, 0].copy(), self.limit)
            if failure is not None:
                return failure
            self._last = (0, first)
        index, start = self._last
        if index + 1 >= count:
            return None
        q, t = data[: self._n, index:count].T.copy(), times[index:count]
        cumulative = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(q, axis=0)) @ self._travel)])
        i0 = 0
        while i0 < len(t) - 1:
            i1 = int(np.searchsorted(cumulative, cumulative[i0] + SPAN_TRAVEL, side="right")) - 1
            i1 = min(max(i1, i0 + 1), len(t) - 1)
            end, failure = self._near(float(t[i1]), q[i1], self.limit + cumulative[i1] - cumulative[i0])
            failure = failure or self._span(t, q, cumulative, i0, i1, start, end)
            if failure is not None:
                return failure
            i0, start = i1, end
        self._last = (count - 1, start)
        return None

    def _failure(self, t: float, q, contact) -> Failure:
        a, b = contact.bodies
        distance = contact.distance
        if distance < 0:
            what = f"put {a} and {b} into each other ({-distance * 1000:.2f} mm deep)"
        else:
            what = f"brought {a} and {b} within {distance * 1000:.2f} mm of each other"
        why = ": the arm left the checked motion (tracking, a disturbance, a limit)" if self._checked else \
            " (the motion was not checked before it started)"
        return Failure(Cause.COLLISION, f"the measured motion {what} at t = {t:.3f} s, closer than half the "
                                        f"clearance ({self.limit * 1000:g} mm){why}",
                       t, tuple(np.asarray(q, dtype=float).tolist()))
