"""The distance between two convex shapes, compiled: support functions and GJK with a certified
lower bound.

Every collision geometry is a convex *core* grown by a *margin* (a radius): a sphere is a point
grown by its radius, a capsule a segment grown by its radius; a box, a cylinder, an ellipsoid and
a convex hull (Drake checks a mesh as the convex hull of its vertices) have no margin. The
distance of two such shapes is that of their cores less both margins (the Minkowski sum of a set
and a ball of radius r moves every boundary point r outwards along its normal).

The distance of the cores is found by GJK (Gilbert, Johnson and Keerthi, "A fast procedure for
computing the distance between complex objects in three-dimensional space", IEEE J. Robotics and
Automation 4(2), 1988; the termination of van den Bergen, "A fast and robust GJK implementation
for collision detection of convex objects", J. Graphics Tools 4(2), 1999) on the Minkowski
difference C = A - B, whose support point in a direction d is s_A(d) - s_B(-d). At each step v is
the point of the current simplex (a subset of C) closest to the origin and w = s_C(-v):

- ||v|| is an upper bound of the distance (v is a point of C);
- (v . w) / ||v|| is a lower bound: every x of C has x . (-v) <= w . (-v), so ||x|| >= x . v /
  ||v|| >= w . v / ||v|| (the supporting plane of C normal to v separates it from the origin).

The kernel returns the largest lower bound met (never above the true distance, up to round-off of
a few 1e-16 m per metre of the shapes' size), stopping when the two bounds are within a tolerance,
when the lower bound reaches a threshold the caller needs no more than, or when the upper bound
falls below one it must not reach. An origin inside the simplex (shapes touching or in each
other) gives 0 for both. The closest point of a simplex to the origin is found by its Voronoi
regions (Ericson, "Real-Time Collision Detection", 2005, sections 5.1.2, 5.1.5, 5.1.6), written here.

Frames: a geometry's core is described in its own frame G (Drake's shape frame: a box, cylinder,
capsule and ellipsoid centred at its origin, the cylinder's and capsule's axis z); its pose in the
world is a row ``pose`` (12,) = [R_WG row-major (9), p_WG (3)] [m]. Lengths in metres.
"""

import math

import numba

from drake_traj.compiled import compiled

__all__ = ["BOX", "CYLINDER", "ELLIPSOID", "HULL", "MAX_ITERATIONS", "POINT", "SEGMENT", "box_gap", "core_distance",
           "inlined", "point_distance", "segment_distance"]

# The kinds of core (geo_i[g, KIND]); their sizes (geo_f[g, SIZE:SIZE + 3]):
POINT = 0  # a sphere's centre: no size (the radius is the margin)
SEGMENT = 1  # a capsule's core along z: [half length, -, -] (the radius is the margin)
BOX = 2  # [half width x, half depth y, half height z]
CYLINDER = 3  # along z: [radius, half length, -]
ELLIPSOID = 4  # [a, b, c], the half axes along x, y, z
HULL = 5  # the vertices vertices[start:start + count] in G

# Columns of the integer and float geometry tables (geo_i (G, 4), geo_f (G, 27)): X_BG [R row-major
# (9), p (3)], the core's sizes, its margin, a bounding capsule of the whole shape (centre c and
# half axis s in B: the segment c ± s; its radius), the radius of a sphere about c holding it
# (|s| + the capsule's radius) and, for a geometry fixed in the world (BODY -1: X_BG is X_WG, c and
# s in the world), the half sizes of a world-aligned box about c holding it.
KIND, BODY, VERTEX_START, VERTEX_COUNT = 0, 1, 2, 3
X_BG, SIZE, MARGIN, CAPSULE, CAPSULE_RADIUS, RADIUS, AABB = 0, 12, 15, 16, 22, 23, 24
GEOMETRY_FLOATS = 27



def inlined(function):
    """``function`` compiled by numba to be inlined into its compiled callers (numba's
    ``inline="always"``, IEEE semantics as :func:`~drake_traj.compiled.compiled`): the small helpers
    of the hot loops. A call between compiled functions that takes arrays costs tens of ns (the
    arguments' reference counts, the call itself), more than a helper's own work; inlined, they
    cost nothing, and the cached kernels that inline them carry their code (a helper of another
    module through the kernels' ``sources_digest``)."""
    return numba.njit(inline="always", error_model="numpy")(function)


MAX_ITERATIONS = 64  # GJK steps; a polytope pair ends in far fewer, a curved one is left conservative
_TOUCHING = 1e-12  # [m] a simplex this close to the origin: the cores touch (or overlap)


@inlined
def _core_support(g, geo_i, geo_f, vertices, dx, dy, dz):
    """The point of geometry g's core (in G) farthest along the direction (dx, dy, dz) (in G): its
    support point."""
    kind = geo_i[g, KIND]
    if kind == POINT:
        return 0.0, 0.0, 0.0
    if kind == SEGMENT:
        return 0.0, 0.0, geo_f[g, SIZE] if dz >= 0.0 else -geo_f[g, SIZE]
    if kind == BOX:
        hx, hy, hz = geo_f[g, SIZE], geo_f[g, SIZE + 1], geo_f[g, SIZE + 2]
        return hx if dx >= 0.0 else -hx, hy if dy >= 0.0 else -hy, hz if dz >= 0.0 else -hz
    if kind == CYLINDER:  # the rim point on the cap facing d
        radius, half = geo_f[g, SIZE], geo_f[g, SIZE + 1]
        z = half if dz >= 0.0 else -half
        radial = math.sqrt(dx * dx + dy * dy)
        if radial == 0.0:
            return 0.0, 0.0, z
        return radius * dx / radial, radius * dy / radial, z
    if kind == ELLIPSOID:  # x = diag(a², b², c²) d / ||diag(a, b, c) d||
        a, b, c = geo_f[g, SIZE], geo_f[g, SIZE + 1], geo_f[g, SIZE + 2]
        ax, by, cz = a * dx, b * dy, c * dz
        norm = math.sqrt(ax * ax + by * by + cz * cz)
        if norm == 0.0:
            return a, 0.0, 0.0
        return a * ax / norm, b * by / norm, c * cz / norm
    start = geo_i[g, VERTEX_START]  # HULL: the vertex farthest along d
    best, chosen = -math.inf, start
    for k in range(start, start + geo_i[g, VERTEX_COUNT]):
        value = vertices[k, 0] * dx + vertices[k, 1] * dy + vertices[k, 2] * dz
        if value > best:
            best, chosen = value, k
    return vertices[chosen, 0], vertices[chosen, 1], vertices[chosen, 2]


@inlined
def _support(g, geo_i, geo_f, vertices, poses, dx, dy, dz):
    """The world support point of geometry g's core along the world direction (dx, dy, dz):
    R s_G(R^T d) + p with R, p its world pose (``poses[g]``)."""
    lx = poses[g, 0] * dx + poses[g, 3] * dy + poses[g, 6] * dz
    ly = poses[g, 1] * dx + poses[g, 4] * dy + poses[g, 7] * dz
    lz = poses[g, 2] * dx + poses[g, 5] * dy + poses[g, 8] * dz
    sx, sy, sz = _core_support(g, geo_i, geo_f, vertices, lx, ly, lz)
    return (poses[g, 0] * sx + poses[g, 1] * sy + poses[g, 2] * sz + poses[g, 9],
            poses[g, 3] * sx + poses[g, 4] * sy + poses[g, 5] * sz + poses[g, 10],
            poses[g, 6] * sx + poses[g, 7] * sy + poses[g, 8] * sz + poses[g, 11])


@inlined
def _keep(w, indices, count):
    """Keep the simplex points w[indices[:count]] (in that order) as w[:count]."""
    for k in range(count):
        i = indices[k]
        w[4 + k, 0], w[4 + k, 1], w[4 + k, 2] = w[i, 0], w[i, 1], w[i, 2]  # rows 4-6 as scratch: count <= 3
    for k in range(count):
        w[k, 0], w[k, 1], w[k, 2] = w[4 + k, 0], w[4 + k, 1], w[4 + k, 2]


@inlined
def _closest_segment(w, a, b):
    """(t, region) of the point of segment w[a] w[b] closest to the origin: a + t (b - a);
    region 1: vertex a, 2: vertex b, 3: inside (Ericson 5.1.2)."""
    ex, ey, ez = w[b, 0] - w[a, 0], w[b, 1] - w[a, 1], w[b, 2] - w[a, 2]
    length2 = ex * ex + ey * ey + ez * ez
    along = -(w[a, 0] * ex + w[a, 1] * ey + w[a, 2] * ez)
    if length2 <= 0.0 or along <= 0.0:
        return 0.0, 1
    if along >= length2:
        return 1.0, 2
    return along / length2, 3


@inlined
def _closest_triangle(w, a, b, c):
    """(u, v, t, code) of the point of triangle w[a] w[b] w[c] closest to the origin: the
    barycentric weights (u of a, v of b, t of c) and the vertices kept (bits 1: a, 2: b, 4: c),
    by the triangle's Voronoi regions (Ericson 5.1.5)."""
    abx, aby, abz = w[b, 0] - w[a, 0], w[b, 1] - w[a, 1], w[b, 2] - w[a, 2]
    acx, acy, acz = w[c, 0] - w[a, 0], w[c, 1] - w[a, 1], w[c, 2] - w[a, 2]
    d1 = -(abx * w[a, 0] + aby * w[a, 1] + abz * w[a, 2])  # ab . (origin - a)
    d2 = -(acx * w[a, 0] + acy * w[a, 1] + acz * w[a, 2])
    if d1 <= 0.0 and d2 <= 0.0:
        return 1.0, 0.0, 0.0, 1
    d3 = -(abx * w[b, 0] + aby * w[b, 1] + abz * w[b, 2])  # ab . (origin - b)
    d4 = -(acx * w[b, 0] + acy * w[b, 1] + acz * w[b, 2])
    if d3 >= 0.0 and d4 <= d3:
        return 0.0, 1.0, 0.0, 2
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:  # edge ab
        s = d1 / (d1 - d3)
        return 1.0 - s, s, 0.0, 3
    d5 = -(abx * w[c, 0] + aby * w[c, 1] + abz * w[c, 2])  # ab . (origin - c)
    d6 = -(acx * w[c, 0] + acy * w[c, 1] + acz * w[c, 2])
    if d6 >= 0.0 and d5 <= d6:
        return 0.0, 0.0, 1.0, 4
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:  # edge ac
        s = d2 / (d2 - d6)
        return 1.0 - s, 0.0, s, 5
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:  # edge bc
        s = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 0.0, 1.0 - s, s, 6
    total = va + vb + vc
    if total == 0.0:  # a degenerate triangle not caught above: vertex a (a point of the set: a safe upper bound)
        return 1.0, 0.0, 0.0, 1
    return va / total, vb / total, vc / total, 7


@inlined
def _triangle_point(w, a, b, c, u, v, t):
    return (u * w[a, 0] + v * w[b, 0] + t * w[c, 0], u * w[a, 1] + v * w[b, 1] + t * w[c, 1],
            u * w[a, 2] + v * w[b, 2] + t * w[c, 2])


@inlined
def _outside_face(w, a, b, c, d):
    """Whether the origin lies strictly on the other side of the plane of face (a, b, c) than vertex d
    (a degenerate tetrahedron counts as outside: its closest point is then on a face)."""
    abx, aby, abz = w[b, 0] - w[a, 0], w[b, 1] - w[a, 1], w[b, 2] - w[a, 2]
    acx, acy, acz = w[c, 0] - w[a, 0], w[c, 1] - w[a, 1], w[c, 2] - w[a, 2]
    nx, ny, nz = aby * acz - abz * acy, abz * acx - abx * acz, abx * acy - aby * acx
    side_origin = -(nx * w[a, 0] + ny * w[a, 1] + nz * w[a, 2])
    side_d = nx * (w[d, 0] - w[a, 0]) + ny * (w[d, 1] - w[a, 1]) + nz * (w[d, 2] - w[a, 2])
    return side_origin * side_d <= 0.0


@inlined
def _reduce(w, count, keep):
    """The point v of the simplex w[:count] closest to the origin; w reduced to the smallest face
    holding it. Returns (vx, vy, vz, count); count 4: the origin is inside the tetrahedron."""
    if count == 1:
        return w[0, 0], w[0, 1], w[0, 2], 1
    if count == 2:
        t, region = _closest_segment(w, 0, 1)
        if region == 1:
            return w[0, 0], w[0, 1], w[0, 2], 1
        if region == 2:
            w[0, 0], w[0, 1], w[0, 2] = w[1, 0], w[1, 1], w[1, 2]
            return w[0, 0], w[0, 1], w[0, 2], 1
        return (w[0, 0] + t * (w[1, 0] - w[0, 0]), w[0, 1] + t * (w[1, 1] - w[0, 1]),
                w[0, 2] + t * (w[1, 2] - w[0, 2]), 2)
    if count == 3:
        return _reduce_face(w, 0, 1, 2, keep)
    best, best_face = math.inf, -1  # a tetrahedron: the nearest of the faces the origin is outside of
    faces = ((0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0))
    for f in range(4):
        a, b, c, d = faces[f]
        if _outside_face(w, a, b, c, d):
            u, v, t, _ = _closest_triangle(w, a, b, c)
            px, py, pz = _triangle_point(w, a, b, c, u, v, t)
            distance2 = px * px + py * py + pz * pz
            if distance2 < best:
                best, best_face = distance2, f
    if best_face < 0:
        return 0.0, 0.0, 0.0, 4
    a, b, c, _ = faces[best_face]
    return _reduce_face(w, a, b, c, keep)


@inlined
def _reduce_face(w, a, b, c, keep):
    """:func:`_reduce` on the triangle w[a] w[b] w[c]: its closest point, w reduced to the vertices kept."""
    u, v, t, code = _closest_triangle(w, a, b, c)
    px, py, pz = _triangle_point(w, a, b, c, u, v, t)
    count = 0
    for bit, index in ((1, a), (2, b), (4, c)):
        if code & bit:
            keep[count] = index
            count += 1
    _keep(w, keep, count)
    return px, py, pz, count


@compiled
def core_distance(ga, gb, geo_i, geo_f, vertices, poses, w, keep, vx, vy, vz, stop_above, stop_below, tolerance):
    """(lower, upper) bounds [m] of the distance between the cores of geometries ``ga`` and
    ``gb`` at world poses ``poses`` (G, 12) by GJK (module docstring), from the first direction v
    (a guess of the closest points' difference a - b, any non-zero vector): ``lower`` <= distance
    <= ``upper``; 0, 0 when the cores touch or overlap. Stops once upper - lower <= ``tolerance``,
    lower >= ``stop_above`` or upper < ``stop_below``; ``w`` (7, 3) and ``keep`` (3,) are scratch."""
    if vx == 0.0 and vy == 0.0 and vz == 0.0:
        vx = 1.0  # any first direction: the lower bound holds for every v
    lower, upper, count = -math.inf, math.inf, 0
    for _ in range(MAX_ITERATIONS):
        ax, ay, az = _support(ga, geo_i, geo_f, vertices, poses, -vx, -vy, -vz)
        bx, by, bz = _support(gb, geo_i, geo_f, vertices, poses, vx, vy, vz)
        wx, wy, wz = ax - bx, ay - by, az - bz  # s_C(-v), C = A - B
        norm = math.sqrt(vx * vx + vy * vy + vz * vz)
        lower = max(lower, (vx * wx + vy * wy + vz * wz) / norm)
        if lower >= stop_above or upper - lower <= tolerance:
            break
        for k in range(count):  # w already in the simplex: no progress is possible
            if w[k, 0] == wx and w[k, 1] == wy and w[k, 2] == wz:
                return max(lower, 0.0), upper
        w[count, 0], w[count, 1], w[count, 2] = wx, wy, wz
        vx, vy, vz, count = _reduce(w, count + 1, keep)
        norm = math.sqrt(vx * vx + vy * vy + vz * vz)
        if count == 4 or norm <= _TOUCHING:
            return 0.0, 0.0
        if norm >= upper:  # no strict decrease: round-off stalls the search; the bound found stands
            break
        upper = norm
        if upper < stop_below:
            break
    return max(lower, 0.0), upper




@inlined
def segment_distance(ax, ay, az, ux, uy, uz, bx, by, bz, vx, vy, vz):
    """(distance [m], dx, dy, dz) between the segments a ± u and b ± v (centres, half vectors), d
    the difference of their closest points (a side minus b side): the least of |r + s u - t v|
    over s, t in [-1, 1] (r = a - b), a convex quadratic on a square. Not parallel: its
    unconstrained minimum's s clamped, the best t for it clamped, the best s for that t clamped
    (Ericson, "Real-Time Collision Detection", section 5.1.9); (nearly) parallel: the least over
    the square's four edges (an end of one segment against the other), where the minimum then lies."""
    rx, ry, rz = ax - bx, ay - by, az - bz
    uu, vv, uv = ux * ux + uy * uy + uz * uz, vx * vx + vy * vy + vz * vz, ux * vx + uy * vy + uz * vz
    ur, vr = ux * rx + uy * ry + uz * rz, vx * rx + vy * ry + vz * rz
    s, t = 0.0, 0.0
    if uu > 0.0 and vv > 0.0 and uu * vv - uv * uv > 1e-12 * uu * vv:
        s = min(max((uv * vr - ur * vv) / (uu * vv - uv * uv), -1.0), 1.0)
        t = (uv * s + vr) / vv
        if t < -1.0 or t > 1.0:
            t = min(max(t, -1.0), 1.0)
            s = min(max((uv * t - ur) / uu, -1.0), 1.0)
    else:
        best = math.inf
        for edge in range(4):  # s = -1, 1 with the best t; t = -1, 1 with the best s
            end = -1.0 if edge % 2 == 0 else 1.0
            if edge < 2:
                s_edge, t_edge = end, min(max((uv * end + vr) / vv, -1.0), 1.0) if vv > 0.0 else 0.0
            else:
                s_edge, t_edge = min(max((uv * end - ur) / uu, -1.0), 1.0) if uu > 0.0 else 0.0, end
            ex, ey, ez = rx + s_edge * ux - t_edge * vx, ry + s_edge * uy - t_edge * vy, rz + s_edge * uz - t_edge * vz
            if ex * ex + ey * ey + ez * ez < best:
                best, s, t = ex * ex + ey * ey + ez * ez, s_edge, t_edge
    dx, dy, dz = rx + s * ux - t * vx, ry + s * uy - t * vy, rz + s * uz - t * vz
    return math.sqrt(dx * dx + dy * dy + dz * dz), dx, dy, dz


@inlined
def box_gap(g, geo_f, poses, cx, cy, cz, ux, uy, uz, radius):
    """(gap [m], nx, ny, nz): the largest separation, along one of box g's axes n (world), of its
    projection from that of the capsule c ± u of ``radius`` (world); a lower bound of their
    distance (a separating axis), n pointing from the box to the capsule."""
    best, nx, ny, nz = -math.inf, 0.0, 0.0, 1.0
    for i in range(3):
        ax, ay, az = poses[g, i], poses[g, 3 + i], poses[g, 6 + i]  # the box's axis i: column i of R_WG
        along = ax * (cx - poses[g, 9]) + ay * (cy - poses[g, 10]) + az * (cz - poses[g, 11])
        gap = abs(along) - geo_f[g, SIZE + i] - abs(ax * ux + ay * uy + az * uz) - radius
        if gap > best:
            sign = 1.0 if along >= 0.0 else -1.0
            best, nx, ny, nz = gap, sign * ax, sign * ay, sign * az
    return best, nx, ny, nz


@inlined
def point_distance(g, geo_i, geo_f, poses, px, py, pz):
    """The signed distance [m] of the world point p from geometry g (negative inside), exact for
    a box and a cylinder (whose cores are the shapes), +inf for any other kind (no bound)."""
    kind = geo_i[g, KIND]
    if kind != BOX and kind != CYLINDER:
        return math.inf
    rx, ry, rz = px - poses[g, 9], py - poses[g, 10], pz - poses[g, 11]
    x = poses[g, 0] * rx + poses[g, 3] * ry + poses[g, 6] * rz  # p in G: R^T (p - p_WG)
    y = poses[g, 1] * rx + poses[g, 4] * ry + poses[g, 7] * rz
    z = poses[g, 2] * rx + poses[g, 5] * ry + poses[g, 8] * rz
    if kind == BOX:  # outside: to the clamped point; inside: minus the depth under the nearest face
        ox, oy, oz = abs(x) - geo_f[g, SIZE], abs(y) - geo_f[g, SIZE + 1], abs(z) - geo_f[g, SIZE + 2]
        return math.sqrt(max(ox, 0.0) ** 2 + max(oy, 0.0) ** 2 + max(oz, 0.0) ** 2) + min(max(ox, oy, oz), 0.0)
    radial, axial = math.sqrt(x * x + y * y) - geo_f[g, SIZE], abs(z) - geo_f[g, SIZE + 1]
    return math.sqrt(max(radial, 0.0) ** 2 + max(axial, 0.0) ** 2) + min(max(radial, axial), 0.0)
