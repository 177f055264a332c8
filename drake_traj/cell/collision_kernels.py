"""The compiled collision model's kernels: forward kinematics of the plant's tree, the broad and
narrow phase of every checked pair, batches of configurations and the conservative advancement
along a joint segment.

The model is data (built by :class:`~drake_traj.cell.compiled_model.CompiledCollisionModel` from
a :class:`~drake_traj.cell.clearance.CellChecker`'s plant and SceneGraph):

- ``links_i`` (L, 4) int [parent link (-1: the parent is fixed in the world, its pose folded into
  X_PF'), joint kind (:data:`FIXED`, :data:`REVOLUTE`, :data:`PRISMATIC`), index of the joint's
  position in q, whether X_MB' is not the identity] and ``links_f`` (L, 24) [X_PF' (12), X_MB'
  (12)] of every moving body, parents first: X_WB = X_WP X_PF X_FM(q) X_MB, F the joint's frame on
  the parent, M on the child (X_MB the inverse of the child frame's fixed pose in B), X_FM a turn q
  [rad] about the unit axis a (in F and M) or a shift q [m] along it (Drake's RevoluteJoint,
  PrismaticJoint); with A a rotation taking z to a, X_FM = [A, 0] Z(q) [Aᵀ, 0] (Z a turn about or
  a shift along z), so X_PF' = X_PF [A, 0] and X_MB' = [Aᵀ, 0] X_MB (a weld's or a fixed joint's
  X_FM X_MB folded into X_PF', X_MB' = I);
- ``geo_i``, ``geo_f``, ``vertices``: the geometries (:mod:`.convex_distance`'s layout; a
  geometry's BODY is its moving link, -1 for one fixed in the world, whose X_BG is then X_WG);
- ``pairs`` (P, 4) int [geometry a, geometry b, link of a, link of b]: the pairs SceneGraph
  checks, none of two geometries fixed in the world; the links are those of
  :func:`~drake_traj.cell.clearance.link_reach` (0 the base and the world), for the travel bound
  ``pair_travel`` (n + 1, n + 1, n) [m/rad] of the conservative advancement.

A pose is a row (12,) [R row-major (9), p (3)] [m]. Every distance returned is a certified lower
bound of max(signed distance, 0) [m] (:mod:`.convex_distance`); a configuration is clear when
every pair's bound is at least the clearance c and above 0.

A pair is decided by the cheapest test that can: the spheres about its geometries' bounding
capsules and their world-aligned boxes (:func:`_sphere_bound`); the capsules' exact distance and,
for a box, its separating axes (:func:`_fine`, which also gives GJK its first direction); two
spheres or capsules are exact there; a sphere's or capsule's core end closer to a box or cylinder
than the threshold proves the pair too close (:func:`_core_upper`); else GJK
(:func:`~.convex_distance.core_distance`), stopped as soon as the answer is known.

The small helpers of the hot loops are inlined into their callers
(:func:`~.convex_distance.inlined`); the kernels (:func:`~drake_traj.compiled.compiled`, cached on
disk) are the entry points and the narrow phase. numba caches a function under its own source file
only (numba issue #1833): each kernel below that reaches :mod:`.convex_distance` (its code inlined,
or GJK called) is made in a closure over that file's digest (``dependencies``, numba's cache key:
:mod:`drake_traj.compiled`).
"""

import math

import numpy as np

from drake_traj.cell import convex_distance
from drake_traj.cell.convex_distance import (AABB, BODY, BOX, CAPSULE, CAPSULE_RADIUS, KIND, MARGIN, RADIUS, SEGMENT,
                                             X_BG, box_gap, core_distance, inlined, point_distance, segment_distance)
from drake_traj.compiled import compiled, sources_digest

__all__ = ["FIXED", "PRISMATIC", "REVOLUTE", "distances_many", "link_poses", "pair_bounds_into", "pair_distances_into",
           "segment_valid", "valid_many"]

FIXED, REVOLUTE, PRISMATIC = 0, 1, 2
PARENT, JOINT_KIND, Q_INDEX, MOVED_BODY = 0, 1, 2, 3  # columns of links_i (MOVED_BODY: X_MB' is not I)
X_PF, X_MB = 0, 12  # columns of links_f: X_PF' and X_MB' (link_poses)
LINK_INTS, LINK_FLOATS = 4, 24
MAX_STEPS = 1_000_000  # advancement steps of one segment before it is refused (a clearance of 0 near contact)
# GJK's stopping gap in the advancement, as a fraction of max(d - c, c/2) (d from below: the fine
# bound): a pair's step from a distance known within it is at most 10 % shorter; a pair found under
# c at it is decided at the model's tolerance.
ADVANCE_TOLERANCE = 0.1
_FLOOR = 1e-12  # [m] the least bound that counts as clear at a clearance of 0; [m] the least travel rate

DEPENDENCY_SOURCES = (convex_distance.__file__, )
_DEPENDENCIES = sources_digest(*DEPENDENCY_SOURCES)

# The model is the tuple (links_i, links_f, geo_i, geo_f, vertices, pairs) (module docstring),
# unpacked by the kernels called from Python: the helpers take arrays, not tuples (a tuple of arrays
# passed to a compiled function costs tens of ns per call). A call's work space is links (L + 1, 12),
# the geometries' poses (G + 1, 13) and their bounding capsules (G, 9) [world centre, half axis, half
# sizes of a world-aligned box about the centre holding the geometry], and GJK's scratch w (7, 3),
# keep (3,). The capsules are made at each configuration (:func:`_prepare`), a moving geometry's
# pose only when a test needs it (:func:`_pose`): poses[g, 12] is the number of the configuration
# it was made at, poses[G, 12] the current one's.


@inlined
def _compose(a, i, column_a, b, j, column_b, out, k):
    """out[k] = a[i] b[j] for poses stored from columns ``column_a`` and ``column_b`` of rows i, j
    (both read into locals first: out may be a or b)."""
    a0, a1, a2, a3 = a[i, column_a], a[i, column_a + 1], a[i, column_a + 2], a[i, column_a + 3]
    a4, a5, a6, a7 = a[i, column_a + 4], a[i, column_a + 5], a[i, column_a + 6], a[i, column_a + 7]
    a8, a9, a10, a11 = a[i, column_a + 8], a[i, column_a + 9], a[i, column_a + 10], a[i, column_a + 11]
    b0, b1, b2, b3 = b[j, column_b], b[j, column_b + 1], b[j, column_b + 2], b[j, column_b + 3]
    b4, b5, b6, b7 = b[j, column_b + 4], b[j, column_b + 5], b[j, column_b + 6], b[j, column_b + 7]
    b8, b9, b10, b11 = b[j, column_b + 8], b[j, column_b + 9], b[j, column_b + 10], b[j, column_b + 11]
    out[k, 0], out[k, 1], out[k, 2] = a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8
    out[k, 3], out[k, 4], out[k, 5] = a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8
    out[k, 6], out[k, 7], out[k, 8] = a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8
    out[k, 9] = a0 * b9 + a1 * b10 + a2 * b11 + a9
    out[k, 10] = a3 * b9 + a4 * b10 + a5 * b11 + a10
    out[k, 11] = a6 * b9 + a7 * b10 + a8 * b11 + a11


@inlined
def link_poses(q, links_i, links_f, out):
    """X_WB (12,) of every moving link into ``out`` (L + 1, 12; the last row scratch) at joint
    positions ``q`` [rad, m] (module docstring): X_WB = X_WP X_PF' Z(q) X_MB', the joint's axis
    turned onto z, so that Z(q) is a turn q about z (R_WM's first two columns mixed by cos q,
    sin q) or a shift q along z; X_MB' skipped where it is the identity."""
    scratch = out.shape[0] - 1
    for k in range(links_i.shape[0]):
        parent, kind = links_i[k, PARENT], links_i[k, JOINT_KIND]
        if parent < 0:
            for i in range(12):
                out[k, i] = links_f[k, X_PF + i]
        else:
            _compose(out, parent, 0, links_f, k, X_PF, out, k)  # X_WF'
        if kind == REVOLUTE:
            c, s = math.cos(q[links_i[k, Q_INDEX]]), math.sin(q[links_i[k, Q_INDEX]])
            for i in range(3):  # R_WF' Rz(q): columns x' = c x + s y, y' = -s x + c y
                column_x, column_y = out[k, 3 * i], out[k, 3 * i + 1]
                out[k, 3 * i], out[k, 3 * i + 1] = c * column_x + s * column_y, c * column_y - s * column_x
        elif kind == PRISMATIC:
            shift = q[links_i[k, Q_INDEX]]
            for i in range(3):
                out[k, 9 + i] += out[k, 3 * i + 2] * shift
        if links_i[k, MOVED_BODY]:
            for i in range(12):
                out[scratch, i] = out[k, i]
            _compose(out, scratch, 0, links_f, k, X_MB, out, k)


@compiled
def _workspace(links_i, geo_i, geo_f):
    """(links, poses, capsules) of a call, the geometries fixed in the world filled in."""
    count = geo_i.shape[0]
    poses, capsules = np.full((count + 1, 13), -1.0), np.empty((count, 9))
    for g in range(count):
        if geo_i[g, BODY] < 0:
            for i in range(12):
                poses[g, i] = geo_f[g, X_BG + i]
            for i in range(6):
                capsules[g, i] = geo_f[g, CAPSULE + i]
            for i in range(3):
                capsules[g, 6 + i] = geo_f[g, AABB + i]
    return np.empty((links_i.shape[0] + 1, 12)), poses, capsules


@inlined
def _prepare(q, links_i, links_f, geo_i, geo_f, links, poses, capsules):
    """The links' poses at ``q`` and every moving geometry's bounding capsule in the world (c_W =
    R_WB c_B + p_WB, s_W = R_WB s_B) with the capsule's world-aligned box (half sizes |s_W| + r);
    the geometries' poses made stale."""
    link_poses(q, links_i, links_f, links)
    poses[geo_i.shape[0], 12] += 1.0
    for g in range(geo_i.shape[0]):
        body = geo_i[g, BODY]
        if body >= 0:
            cx, cy, cz = geo_f[g, CAPSULE], geo_f[g, CAPSULE + 1], geo_f[g, CAPSULE + 2]
            sx, sy, sz, radius = geo_f[g, CAPSULE + 3], geo_f[g, CAPSULE + 4], geo_f[g, CAPSULE + 5], geo_f[g, CAPSULE_RADIUS]
            for i in range(3):
                r0, r1, r2 = links[body, 3 * i], links[body, 3 * i + 1], links[body, 3 * i + 2]
                capsules[g, i] = r0 * cx + r1 * cy + r2 * cz + links[body, 9 + i]
                axis = r0 * sx + r1 * sy + r2 * sz
                capsules[g, 3 + i] = axis
                capsules[g, 6 + i] = abs(axis) + radius


@inlined
def _pose(g, geo_i, geo_f, links, poses):
    """Geometry g's world pose X_WB X_BG into poses[g], once per configuration."""
    body, now = geo_i[g, BODY], poses[geo_i.shape[0], 12]
    if body >= 0 and poses[g, 12] != now:
        _compose(links, body, 0, geo_f, g, X_BG, poses, g)
        poses[g, 12] = now


@inlined
def _sphere_bound(a, b, geo_f, capsules):
    """A lower bound [m] of the distance of geometries a, b from the spheres about their capsules'
    centres, |c_a - c_b| - ρ_a - ρ_b, and their world-aligned boxes (the largest gap along x, y, z)."""
    dx, dy, dz = capsules[a, 0] - capsules[b, 0], capsules[a, 1] - capsules[b, 1], capsules[a, 2] - capsules[b, 2]
    gap = max(abs(dx) - capsules[a, 6] - capsules[b, 6], abs(dy) - capsules[a, 7] - capsules[b, 7],
              abs(dz) - capsules[a, 8] - capsules[b, 8])
    return max(math.sqrt(dx * dx + dy * dy + dz * dz) - geo_f[a, RADIUS] - geo_f[b, RADIUS], gap)


@inlined
def _core_upper(a, b, geo_i, geo_f, poses, capsules):
    """An upper bound [m] of the distance of geometries a and b when one is a sphere or capsule
    and the other a box or cylinder: the least signed distance of the first's core ends from
    the second, less its radius (a point of the first is that close to the second, or they
    overlap); +inf otherwise."""
    if geo_i[b, KIND] <= SEGMENT:
        a, b = b, a
    if geo_i[a, KIND] > SEGMENT:
        return math.inf
    best = math.inf
    for sign in (-1.0, 1.0):
        best = min(best, point_distance(b, geo_i, geo_f, poses, capsules[a, 0] + sign * capsules[a, 3],
                                        capsules[a, 1] + sign * capsules[a, 4], capsules[a, 2] + sign * capsules[a, 5]))
    return best - geo_f[a, MARGIN]


@inlined
def _fine(a, b, geo_i, geo_f, links, poses, capsules):
    """(bound [m], v): a lower bound of the distance of geometries a and b, the distance of
    their bounding capsules and, for a box, the gap along its axes (separating axes), and the
    direction v (a - b) it was found along, GJK's first. Kept small: the hot loops call it for
    every pair the spheres leave, and :func:`_narrow` only for the few it leaves."""
    ra, rb = geo_f[a, CAPSULE_RADIUS], geo_f[b, CAPSULE_RADIUS]
    distance, vx, vy, vz = segment_distance(capsules[a, 0], capsules[a, 1], capsules[a, 2], capsules[a, 3],
                                            capsules[a, 4], capsules[a, 5], capsules[b, 0], capsules[b, 1],
                                            capsules[b, 2], capsules[b, 3], capsules[b, 4], capsules[b, 5])
    bound = distance - ra - rb
    if geo_i[a, KIND] == BOX:  # the normal points from a to b: v = a - b along -n
        _pose(a, geo_i, geo_f, links, poses)
        gap, nx, ny, nz = box_gap(a, geo_f, poses, capsules[b, 0], capsules[b, 1], capsules[b, 2], capsules[b, 3],
                                  capsules[b, 4], capsules[b, 5], rb)
        if gap > bound:
            bound, vx, vy, vz = gap, -nx, -ny, -nz
    if geo_i[b, KIND] == BOX:
        _pose(b, geo_i, geo_f, links, poses)
        gap, nx, ny, nz = box_gap(b, geo_f, poses, capsules[a, 0], capsules[a, 1], capsules[a, 2], capsules[a, 3],
                                  capsules[a, 4], capsules[a, 5], ra)
        if gap > bound:
            bound, vx, vy, vz = gap, nx, ny, nz
    if vx == 0.0 and vy == 0.0 and vz == 0.0:  # the capsules meet: their centres' difference
        vx, vy, vz = capsules[a, 0] - capsules[b, 0], capsules[a, 1] - capsules[b, 1], capsules[a, 2] - capsules[b, 2]
    return bound, vx, vy, vz


def _narrow_with(dependencies):
    @compiled
    def narrow(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bound, vx, vy, vz, stop_above, stop_below,
               tolerance):
        """(lower, upper) [m] of the distance of geometries a and b (margins taken off; lower at
        least 0) past :func:`_fine`'s ``bound`` along v: exact for two spheres or capsules (their
        own capsules), a cheap proof of nearness (:func:`_core_upper`), else GJK
        (:func:`~.convex_distance.core_distance`) from v, stopping as there."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        if geo_i[a, KIND] <= SEGMENT and geo_i[b, KIND] <= SEGMENT:  # spheres and capsules: their own capsules
            return max(bound, 0.0), bound
        _pose(a, geo_i, geo_f, links, poses)
        _pose(b, geo_i, geo_f, links, poses)
        if stop_below > bound:  # a cheap proof that the pair is closer than stop_below
            upper = _core_upper(a, b, geo_i, geo_f, poses, capsules)
            if upper < stop_below:
                return max(bound, 0.0), upper
        margin = geo_f[a, MARGIN] + geo_f[b, MARGIN]
        lower, upper = core_distance(a, b, geo_i, geo_f, vertices, poses, w, keep, vx, vy, vz, stop_above + margin,
                                     stop_below + margin, tolerance)
        return max(lower - margin, bound, 0.0), upper - margin

    return narrow


_narrow = _narrow_with(_DEPENDENCIES)


def _pair_bounds_with(dependencies):
    @compiled
    def pair_bounds(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, stop_above, stop_below, tolerance):
        """(lower, upper) [m] of the distance of geometries a and b: :func:`_fine`, then
        :func:`_narrow` unless the fine bound already reaches ``stop_above``."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        bound, vx, vy, vz = _fine(a, b, geo_i, geo_f, links, poses, capsules)
        if bound >= stop_above:
            return bound, math.inf
        return _narrow(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bound, vx, vy, vz, stop_above,
                       stop_below, tolerance)

    return pair_bounds


_pair_bounds = _pair_bounds_with(_DEPENDENCIES)


@inlined
def _clear(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, clearance, tolerance, order):
    """Whether every pair's lower bound is at least ``clearance`` [m] and above 0 at the
    prepared configuration. The pairs are tried in the order ``order`` (a permutation of the
    pairs' rows), and one found too close is moved to its front: the pairs that refuse
    configurations are few, and then tried first."""
    needed = max(clearance, _FLOOR)
    for k in range(order.shape[0]):
        p = order[k]
        a, b = pairs[p, 0], pairs[p, 1]
        if _sphere_bound(a, b, geo_f, capsules) >= needed:
            continue
        bound, vx, vy, vz = _fine(a, b, geo_i, geo_f, links, poses, capsules)
        if bound >= needed:
            continue
        lower, _ = _narrow(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bound, vx, vy, vz, needed,
                           clearance, tolerance)
        if lower < needed:
            for i in range(k, 0, -1):
                order[i] = order[i - 1]
            order[0] = p
            return False
    return True


@inlined
def _nearest(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bounds, look_ahead, tolerance):
    """The smallest pair distance [m] at the prepared configuration, at most ``look_ahead``:
    the pair the spheres put nearest first, then only the pairs whose sphere bound is below
    the least so far (each stopping once it cannot lower it). ``bounds`` (P,) is scratch."""
    first, least = -1, math.inf
    for p in range(pairs.shape[0]):
        bounds[p] = _sphere_bound(pairs[p, 0], pairs[p, 1], geo_f, capsules)
        if bounds[p] < least:
            first, least = p, bounds[p]
    best = look_ahead
    for k in range(-1, pairs.shape[0]):
        p = first if k < 0 else k
        if p < 0 or (k >= 0 and p == first) or bounds[p] >= best:
            continue
        a, b = pairs[p, 0], pairs[p, 1]
        bound, vx, vy, vz = _fine(a, b, geo_i, geo_f, links, poses, capsules)
        if bound >= best:
            continue
        lower, _ = _narrow(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bound, vx, vy, vz, best,
                           -math.inf, tolerance)
        best = min(best, lower)
    return best


def _distances_many_with(dependencies):
    @compiled
    def distances_many(configurations, model, look_ahead, tolerance, out):
        """The smallest pair distance [m] (at most ``look_ahead``) of each row of ``configurations``
        (m, n) [rad, m] into ``out`` (m,)."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        links_i, links_f, geo_i, geo_f, vertices, pairs = model
        links, poses, capsules = _workspace(links_i, geo_i, geo_f)
        w, keep, bounds = np.empty((7, 3)), np.empty(3, dtype=np.int64), np.empty(pairs.shape[0])
        for m in range(configurations.shape[0]):
            _prepare(configurations[m], links_i, links_f, geo_i, geo_f, links, poses, capsules)
            out[m] = _nearest(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bounds, look_ahead, tolerance)

    return distances_many


distances_many = _distances_many_with(_DEPENDENCIES)


def _valid_many_with(dependencies):
    @compiled
    def valid_many(configurations, lower, upper, model, clearance, tolerance, out):
        """Per row of ``configurations`` (m, n): inside [``lower``, ``upper``] and every pair at
        least ``clearance`` [m] apart (and apart at all), into ``out`` (m,) bool."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        links_i, links_f, geo_i, geo_f, vertices, pairs = model
        links, poses, capsules = _workspace(links_i, geo_i, geo_f)
        w, keep, order = np.empty((7, 3)), np.empty(3, dtype=np.int64), np.arange(pairs.shape[0])
        for m in range(configurations.shape[0]):
            inside = True
            for j in range(configurations.shape[1]):
                if not (lower[j] <= configurations[m, j] <= upper[j]):  # NaN too
                    inside = False
            if inside:
                _prepare(configurations[m], links_i, links_f, geo_i, geo_f, links, poses, capsules)
                inside = _clear(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, clearance, tolerance, order)
            out[m] = inside

    return valid_many


valid_many = _valid_many_with(_DEPENDENCIES)


def _pair_distances_into_with(dependencies):
    @compiled
    def pair_distances_into(q, model, look_ahead, tolerance, distances, indices):
        """The pairs closer than ``look_ahead`` [m] at ``q``: their distances [m] into
        ``distances`` and their rows of the pairs into ``indices``; returns how many."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        links_i, links_f, geo_i, geo_f, vertices, pairs = model
        links, poses, capsules = _workspace(links_i, geo_i, geo_f)
        w, keep = np.empty((7, 3)), np.empty(3, dtype=np.int64)
        _prepare(q, links_i, links_f, geo_i, geo_f, links, poses, capsules)
        count = 0
        for p in range(pairs.shape[0]):
            a, b = pairs[p, 0], pairs[p, 1]
            if _sphere_bound(a, b, geo_f, capsules) >= look_ahead:
                continue
            lower, _ = _pair_bounds(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, look_ahead, -math.inf,
                                    tolerance)
            if lower < look_ahead:
                distances[count], indices[count] = lower, p
                count += 1
        return count

    return pair_distances_into


pair_distances_into = _pair_distances_into_with(_DEPENDENCIES)


def _pair_bounds_into_with(dependencies):
    @compiled
    def pair_bounds_into(q, model, tolerance, out):
        """Every pair's (lower, upper) distance bounds [m] at ``q`` into ``out`` (P, 2), GJK run
        to ``tolerance`` whatever the broad phase says (for tests: upper bounds from real points)."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        links_i, links_f, geo_i, geo_f, vertices, pairs = model
        links, poses, capsules = _workspace(links_i, geo_i, geo_f)
        w, keep = np.empty((7, 3)), np.empty(3, dtype=np.int64)
        _prepare(q, links_i, links_f, geo_i, geo_f, links, poses, capsules)
        for p in range(pairs.shape[0]):
            out[p, 0], out[p, 1] = _pair_bounds(pairs[p, 0], pairs[p, 1], geo_i, geo_f, vertices, links, poses, capsules, w,
                                                keep, math.inf, -math.inf, tolerance)

    return pair_bounds_into


pair_bounds_into = _pair_bounds_into_with(_DEPENDENCIES)


@inlined
def _allowed_step(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, travel, clearance, tolerance):
    """The conservative-advancement step (a fraction of the segment) from the prepared
    configuration: the least over the pairs of max(d - c, c/2) / (the pair's travel bound over
    the segment, ``travel`` [m]); -1 when a pair is closer than c (or not apart at c = 0). Each
    pair's GJK stops once its bound cannot lower the least step so far; the pair whose sphere
    bound gives the least step goes first."""
    c = clearance
    needed = max(c, _FLOOR)
    first, least = -1, math.inf
    for p in range(pairs.shape[0]):
        bound = _sphere_bound(pairs[p, 0], pairs[p, 1], geo_f, capsules)
        step = -math.inf if bound < needed else max(bound - c, 0.5 * c) / max(travel[p], _FLOOR)
        if step < least:
            first, least = p, step
    allowed = math.inf
    for k in range(-1, pairs.shape[0]):
        p = first if k < 0 else k
        if p < 0 or (k >= 0 and p == first):
            continue
        a, b = pairs[p, 0], pairs[p, 1]
        rate = max(travel[p], _FLOOR)
        enough = max(c + allowed * rate, needed)  # a distance that cannot lower the step
        if _sphere_bound(a, b, geo_f, capsules) >= enough:
            continue
        bound, vx, vy, vz = _fine(a, b, geo_i, geo_f, links, poses, capsules)
        if bound >= enough:
            continue
        lower, _ = _narrow(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, bound, vx, vy, vz, enough, c,
                           max(tolerance, ADVANCE_TOLERANCE * max(bound - c, 0.5 * c)))
        if lower < needed:  # decided at the model's tolerance
            lower, _ = _pair_bounds(a, b, geo_i, geo_f, vertices, links, poses, capsules, w, keep, needed, c, tolerance)
            if lower < needed:
                return -1.0
        allowed = min(allowed, max(lower - c, 0.5 * c) / rate)
    return allowed


def _segment_valid_with(dependencies):
    @compiled
    def segment_valid(a, b, lower, upper, model, pair_travel, clearance, tolerance):
        """Whether the straight joint segment from ``a`` to ``b`` keeps the clearance c at every
        configuration checked and c/2 between them (:meth:`Scene.segment_valid
        <drake_traj.planners.free.search.Scene.segment_valid>`'s conservative advancement, compiled):
        inside the ranges, clear at u = 1, 0.5, 0.25, 0.75, then from u = 0 on by the pairs' steps
        (:func:`_allowed_step`). ``pair_travel`` (n + 1, n + 1, n) [m/rad]: the relative travel of
        two links per |Δq_j|. More than :data:`MAX_STEPS` steps: refused."""
        dependencies  # noqa: B018 (numba's cache key: drake_traj.compiled.sources_digest)
        links_i, links_f, geo_i, geo_f, vertices, pairs = model
        n = a.shape[0]
        step = b - a
        moving = False
        for j in range(n):
            if not (lower[j] <= min(a[j], b[j]) and max(a[j], b[j]) <= upper[j]):  # NaN too
                return False  # a straight segment between two points inside a box stays inside it
            moving = moving or step[j] != 0.0
        if not moving:
            return True
        links, poses, capsules = _workspace(links_i, geo_i, geo_f)
        w, keep, order = np.empty((7, 3)), np.empty(3, dtype=np.int64), np.arange(pairs.shape[0])
        q = np.empty(n)
        travel = np.zeros(pairs.shape[0])  # [m] each pair's travel bound over the whole segment
        for p in range(pairs.shape[0]):
            for j in range(n):
                travel[p] += pair_travel[pairs[p, 2], pairs[p, 3], j] * abs(step[j])
        looks = (1.0, 0.5, 0.25, 0.75)  # a cheap look at the end and inside first: most refusals end here
        u = looks[0]
        for k in range(MAX_STEPS + len(looks)):
            for j in range(n):
                q[j] = a[j] + u * step[j]
            _prepare(q, links_i, links_f, geo_i, geo_f, links, poses, capsules)
            if k < len(looks):
                if not _clear(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, clearance, tolerance,
                              order):
                    return False
                u = looks[k + 1] if k + 1 < len(looks) else 0.0  # then from a on
                continue
            allowed = _allowed_step(pairs, geo_i, geo_f, vertices, links, poses, capsules, w, keep, travel, clearance,
                                    tolerance)
            if allowed < 0.0:
                return False
            u = min(1.0, u + allowed)
            if u >= 1.0:
                return True  # b was found clear first
        return False

    return segment_valid


segment_valid = _segment_valid_with(_DEPENDENCIES)
