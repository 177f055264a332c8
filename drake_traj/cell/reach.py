"""Travel bounds of a serial arm's collision geometry, from its model: how far any point of the
geometry outboard of a joint can move per unit of that joint's motion (:func:`joint_reach`, per
joint; :func:`link_reach`, per link and joint; :func:`pair_travel`, per pair of links), and the
conservative advancement along a motion that they size (:class:`Advancement`: the cell check's
samples; the free-motion search's segments advance on the same bounds). Lengths in m, turns in rad,
shifts in m.

The argument. A turn of joint j moves a point at distance r from its axis at r |q̇_j|; R_j bounds
that distance for every collision geometry outboard of joint j (for a serial chain R_j =
max(geometry of link j, |offset to joint j+1| + R_{j+1}), from the plant's fixed joint and geometry
poses), a prismatic joint moves points at |q̇_j|. Link b moves relative to link a (a nearer the
base; 0 the base and everything fixed in the world) only by the joints between them, so a point
of b moves in a's frame at most at Σ_j T[a, b, j] |q̇_j| (:func:`pair_travel`: link_reach's
distances, each at most R_j). A signed distance of two bodies is 1-Lipschitz in their relative
displacement, so it changes along a motion by at most the pair's travel, the integral of that
rate (with :data:`TRAVEL_MARGIN`, on the 1 ms grid), and any pair's by at most the arm's travel
bound 1.1 Σ_j R_j ∫|q̇_j| dt. From a sample where a pair is d apart, the next sample at most
d - c + s of its travel further (c the clearance, s the spacing, d >= c) keeps it at least
d - (d - c + s) = c - s apart in between: at least c/2 at the default s = c/2, with long steps
where everything is far apart.
"""

import numpy as np

from drake_traj.cell.shapes import shape_radius
from drake_traj.compiled import compiled

__all__ = ["Advancement", "TRAVEL_MARGIN", "joint_reach", "link_reach", "pair_travel"]

TRAVEL_MARGIN = 1.1
"""The margin on every travel bound: along a motion sampled every millisecond, each step's |Δq_j|
stands for ∫|q̇_j| dt, exact where no joint turns back inside the millisecond; the 10 % covers the
rest."""


def joint_reach(plant, scene_graph, plant_context, instance, joint_names) -> np.ndarray:
    """R_j [m] per joint of a serial chain: a bound on the distance of any collision geometry
    outboard of joint j (on its child link or on bodies welded to it, such as the tool) from
    joint j's origin, which lies on its axis; 1 for a prismatic joint (a point moves at |q̇_j|).
    Poses are fixed in each link, so any ``plant_context`` gives them."""
    inspector = scene_graph.model_inspector()
    joints = [plant.GetJointByName(name, instance) for name in joint_names]
    reach = np.zeros(len(joints))
    outboard = 0.0  # R_{j+1}, added to the offset from joint j to joint j+1
    for j in reversed(range(len(joints))):
        joint = joints[j]
        origin = joint.frame_on_child().CalcPoseInWorld(plant_context)
        link = joint.child_body()
        bound = 0.0
        for body in plant.GetBodiesWeldedTo(link):
            X_OB = origin.InvertAndCompose(body.body_frame().CalcPoseInWorld(plant_context))
            for geometry in plant.GetCollisionGeometriesForBody(body):
                X_OG = X_OB @ inspector.GetPoseInFrame(geometry)
                bound = max(bound, float(np.linalg.norm(X_OG.translation())) + shape_radius(inspector.GetShape(geometry)))
        if j + 1 < len(joints):
            following = joints[j + 1]
            offset = origin.InvertAndCompose(following.frame_on_parent().CalcPoseInWorld(plant_context)).translation()
            stroke = (max(abs(following.position_lower_limits()[0]), abs(following.position_upper_limits()[0]))
                      if following.type_name() == "prismatic" else 0.0)
            bound = max(bound, float(np.linalg.norm(offset)) + stroke + outboard)
        reach[j] = 1.0 if joint.type_name() == "prismatic" else bound
        outboard = bound
    return reach


def link_reach(plant, scene_graph, instance, joint_names) -> tuple[np.ndarray, dict]:
    """Per-link travel bounds of a serial arm: (R [m/rad] (n + 1, n), the link of every
    collision geometry: {GeometryId: link}, 0 for the base and everything fixed in the world).

    R[i, j] bounds the distance of link i's collision geometry (the bodies welded to it, the tool
    on the last link, included) from joint j's origin on its axis, for every joint j that moves
    link i (j < i; joints from 0, link 0 the base): a turn Δq_j moves each of its points at most
    R[i, j] |Δq_j|; a prismatic joint j moves them by |Δq_j| (R[i, j] = 1 [m/m]), and its stroke
    (the larger |limit|) lengthens the distances of the joints before it. From the link's own
    geometry about its joint and the joint-to-joint offsets (the triangle inequality, as
    :func:`joint_reach`, which is the most of these over the links)."""
    inspector = scene_graph.model_inspector()
    context = plant.CreateDefaultContext()
    joints = [plant.GetJointByName(name, instance) for name in joint_names]
    n = len(joints)
    origins = [joint.frame_on_child().CalcPoseInWorld(context) for joint in joints]
    reach = np.zeros((n + 1, n))
    links = {}
    for j, joint in enumerate(joints):
        bound = 0.0
        for body in plant.GetBodiesWeldedTo(joint.child_body()):
            X_OB = origins[j].InvertAndCompose(body.body_frame().CalcPoseInWorld(context))
            for geometry in plant.GetCollisionGeometriesForBody(body):
                links[geometry] = j + 1
                X_OG = X_OB @ inspector.GetPoseInFrame(geometry)
                bound = max(bound, float(np.linalg.norm(X_OG.translation())) + shape_radius(inspector.GetShape(geometry)))
        reach[j + 1, j] = 1.0 if joints[j].type_name() == "prismatic" else bound
        distance = bound  # [m] of link j + 1's geometry from joint k's origin, k from j down
        for k in reversed(range(j)):  # the joints before it: its origin's offset to the next joint's, and on
            offset = origins[k].InvertAndCompose(joints[k + 1].frame_on_parent().CalcPoseInWorld(context)).translation()
            following = joints[k + 1]
            stroke = (max(abs(following.position_lower_limits()[0]), abs(following.position_upper_limits()[0]))
                      if following.type_name() == "prismatic" else 0.0)
            distance += float(np.linalg.norm(offset)) + stroke
            reach[j + 1, k] = 1.0 if joints[k].type_name() == "prismatic" else distance
    return reach, links


def pair_travel(reach: np.ndarray) -> np.ndarray:
    """T [m/rad or m/m] (n + 1, n + 1, n) from :func:`link_reach`'s R (n + 1, n): T[a, b, j] bounds
    how far link b moves relative to link a per |Δq_j| (a turn; a prismatic joint's shift moves
    points by itself), with :data:`TRAVEL_MARGIN`: the joints between the two links move the outer
    one about the inner one; the joints before both, neither. Each entry is at most the margin
    times :func:`joint_reach`'s R_j (the most of link_reach's over the links)."""
    reach = np.asarray(reach, dtype=float)
    n = reach.shape[1]
    travel = np.zeros((n + 1, n + 1, n))
    for a in range(n + 1):
        for b in range(n + 1):
            inner, outer = sorted((a, b))
            if outer > inner:
                travel[a, b, inner:] = TRAVEL_MARGIN * reach[outer, inner:]
    return travel


class Advancement:
    """Travel bounds along a motion given on a grid, and the conservative advancement they allow
    (module docstring).

    Args:
        grid: times [s] (M,), increasing (the cell check's 1 ms grid).
        q: joint positions [rad, m] on the grid (M, n).
        reach: :func:`joint_reach`'s R (n,): the travel bound of any two bodies.
        pair_travel: :func:`pair_travel`'s T (n + 1, n + 1, n): the travel bound of two links.

    A pair is a row of :attr:`rates` [m per rad or m of each joint]: :meth:`row` (a, b) of two
    links, :attr:`ANY` of any two bodies (:data:`TRAVEL_MARGIN` R). :attr:`travel` [m] (M,) is
    the latter from the first time: it bounds every pair's."""

    def __init__(self, grid, q, reach, pair_travel):
        self.grid = np.ascontiguousarray(grid, dtype=float)
        q = np.asarray(q, dtype=float)
        self.links = pair_travel.shape[0]
        self.rates = np.ascontiguousarray(np.concatenate([np.reshape(pair_travel, (-1, q.shape[1])),
                                                          [TRAVEL_MARGIN * np.asarray(reach, dtype=float)]]))
        self.ANY = len(self.rates) - 1
        self.turns = np.concatenate([np.zeros((1, q.shape[1])), np.cumsum(np.abs(np.diff(q, axis=0)), axis=0)])
        self.travel = self.turns @ self.rates[self.ANY]

    def row(self, a, b):
        """The row of the pair of links ``a`` and ``b`` (ints or int arrays)."""
        return a * self.links + b

    def after(self, start: float, rows, allowed) -> float:
        """The latest time [s] (the grid's last at most) up to which no pair of ``rows`` travels
        more than its ``allowed`` [m] from time ``start`` [s]."""
        return _after(self.grid, self.turns, self.rates, np.asarray(rows, dtype=np.int64),
                      np.asarray(allowed, dtype=float), self.ANY, np.inf, 0.0, float(start))[0]

    def step(self, start: float, rows, bounds, measure, clearance: float, spacing: float,
             look_ahead: float) -> tuple[float, float]:
        """One sample's conservative advancement: (the least distance [m] of two bodies at the
        sample at time ``start`` [s], at most ``look_ahead`` [m]; the time [s] of the next
        sample, ``start`` itself where a distance is below ``clearance``). Each pair d apart may
        travel d - ``clearance`` + ``spacing`` [m] to the next sample (module docstring).

        ``bounds`` [m] are lower bounds of the distances of the pairs ``rows`` (the compiled
        model's, up to ``look_ahead``; may be empty): with every other pair
        ``look_ahead`` apart they give a first next time. ``measure(within)`` gives (rows,
        distances [m]) of every pair within ``within`` [m] (SceneGraph's), asked for the distance
        that covers that step on the bound of any two bodies (at least ``clearance``, at most
        ``look_ahead``): each pair takes the smaller of the two, the pairs it does not give are
        ``within`` apart, so ``measure``'s own distances bound every step."""
        offset, rows, bounds = spacing - clearance, np.asarray(rows, dtype=np.int64), np.asarray(bounds, dtype=float)
        first, covered = _after(self.grid, self.turns, self.rates, rows, bounds, self.ANY, look_ahead, offset, start)
        within = min(max(covered - offset, clearance), look_ahead)
        measured_rows, measured = measure(within)
        least = min(float(bounds.min()) if len(bounds) else look_ahead, within, min(measured, default=within))
        if least < clearance:
            return least, start
        if not measured:  # the first time holds: every other pair is beyond within
            return least, first
        rows = np.concatenate([rows, np.asarray(measured_rows, dtype=np.int64)])
        distances = np.concatenate([bounds, measured])
        return least, _after(self.grid, self.turns, self.rates, rows, distances, self.ANY, within, offset, start)[0]


@compiled
def _after(grid, turns, rates, rows, distances, last_row, last_distance, offset, start):
    """The travel of each pair k, rates[rows[k]] · turns (and of ``last_row``'s), linear between the
    grid's times, followed forward from time ``start`` [s] until the first travels its distance
    (distances[k], ``last_distance``) + ``offset`` [m]: (that time (the grid's last at most),
    ``last_row``'s travel [m] from ``start`` to it)."""
    count, n = turns.shape
    pairs = len(rows) + 1
    i = min(max(np.searchsorted(grid, start, side="right") - 1, 0), count - 2)
    w = (start - grid[i]) / (grid[i + 1] - grid[i])
    here = np.empty(pairs)
    target = np.empty(pairs)
    for k in range(pairs):
        row = rows[k] if k < pairs - 1 else last_row
        value = 0.0
        for j in range(n):
            value += rates[row, j] * (turns[i, j] + w * (turns[i + 1, j] - turns[i, j]))
        here[k] = value
        target[k] = value + (distances[k] if k < pairs - 1 else last_distance) + offset
    first_last, before = here[pairs - 1], start
    for m in range(i + 1, count):
        best, last_before = grid[count - 1], here[pairs - 1]
        for k in range(pairs):
            row = rows[k] if k < pairs - 1 else last_row
            value = 0.0
            for j in range(n):
                value += rates[row, j] * turns[m, j]
            if value >= target[k]:
                best = min(best, before + (target[k] - here[k]) / (value - here[k]) * (grid[m] - before))
            here[k] = value
        if best < grid[count - 1]:
            fraction = (best - before) / (grid[m] - before)
            return best, last_before + fraction * (here[pairs - 1] - last_before) - first_last
        before = grid[m]
    return grid[count - 1], here[pairs - 1] - first_last
