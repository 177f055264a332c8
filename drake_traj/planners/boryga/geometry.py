"""The loop path's geometry (Boryga, section 2.2, Table 1): B -> M -> T1 -> arc about O1 -> T2
-> M -> E, the loop circle tangent to the extensions of BM and EM beyond M. Points and vectors in
the base frame xyz [m], angles in rad. See the package docstring for the construction and its
corrections."""

from dataclasses import dataclass

import numpy as np

from drake_traj.validation import finite_array, invalid, positive_scalar

__all__ = ["LoopGeometry", "loop_geometry"]

# sin(angle BME) below this counts as collinear: no corner (angle 0 or pi to within ~1e-7 rad).
# Near those angles the bisector b = a_hat + d_hat (angle pi) or the radius (angle 0) vanish and
# the construction loses all accuracy.
_COLLINEAR_SIN_TOL = 1e-7
# Relative tolerance for a radius and a Delta given together to count as the same loop.
_FIT_RTOL = 1e-9


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _unit(vector: np.ndarray) -> np.ndarray:
    return vector / np.linalg.norm(vector)


@dataclass(frozen=True, eq=False)
class LoopGeometry:
    """Geometry of the path B -> M -> T1 -> (arc) -> T2 -> M -> E (section 2.2, Table 1).

    Built by :func:`loop_geometry`. All points and vectors are in the base frame xyz; arrays are
    read-only copies.

    Attributes:
        B, M, E: start point, corner and end point [m], shape (3,).
        delta: Delta, distance from M to the loop centre O1 [m].
        R: loop radius [m], the distance from O1 to the line BM (and to the line EM).
        corner_angle: the angle BME [rad], in (0, pi).
        a_hat: unit vector of a = M - B (direction of motion on BM and MT1).
        d_hat: unit vector of d = M - E (the motion on T2M and ME is along -d_hat).
        b_hat: unit vector of b = a_hat + d_hat, the bisector of the angle BME, pointing away
            from the corner's inside (towards O1).
        O1: loop centre, M + Delta b_hat [m].
        T1: tangent point on the extension of BM beyond M, M + ds_MT1 a_hat [m].
        T2: tangent point on the extension of EM beyond M, M + ds_T2M d_hat [m].
        beta: arc angle T1 -> T2 about O1 [rad]: pi + the angle between a_hat and d_hat.
        beta_b: start angle of the arc in the xi-eta plane, pi - beta / 2 [rad] (eq. 11; called
            beta_p in the paper's section 3).
        xi, eta, zeta: axes of the local frame of eq. 12 (docs/papers.md): xi = (M - O1) / Delta,
            zeta = unit(a_hat x d_hat), eta = zeta x xi. Right-handed, orthonormal.
        ds_BM, ds_MT1, ds_arc, ds_T2M, ds_ME: path increments of the five parts [m]
            (ds_arc = beta R is the paper's Delta s^A).
    """

    B: np.ndarray
    M: np.ndarray
    E: np.ndarray
    delta: float
    R: float
    corner_angle: float
    a_hat: np.ndarray
    d_hat: np.ndarray
    b_hat: np.ndarray
    O1: np.ndarray
    T1: np.ndarray
    T2: np.ndarray
    beta: float
    beta_b: float
    xi: np.ndarray
    eta: np.ndarray
    zeta: np.ndarray
    ds_BM: float
    ds_MT1: float
    ds_arc: float
    ds_T2M: float
    ds_ME: float

    @property
    def ds_loop(self) -> float:
        """Path length of the whole loop M -> T1 -> T2 -> M [m]."""
        return self.ds_MT1 + self.ds_arc + self.ds_T2M

    @property
    def path_length(self) -> float:
        """Total path length B -> M -> T1 -> T2 -> M -> E [m] (section 2.5)."""
        return self.ds_BM + self.ds_loop + self.ds_ME

    @property
    def transform(self) -> np.ndarray:
        """T of eq. 12: the 4x4 homogeneous transform from xi-eta-zeta (origin O1) to xyz.

        Columns xi, eta, zeta, O1 over the row [0, 0, 0, 1], so S^A = T Xi^A with
        Xi^A = [R cos beta(t), R sin beta(t), 0, 1].
        """
        T = np.eye(4)
        T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = self.xi, self.eta, self.zeta, self.O1
        return T

    def arc_point(self, angle) -> np.ndarray:
        """Point of the loop circle at angle ``angle`` [rad] in the xi-eta plane (eq. 12) [m].

        Args:
            angle: scalar or array of any shape.

        Returns:
            Array of shape angle.shape + (3,).
        """
        angle = np.asarray(angle, dtype=float)[..., None]
        return self.O1 + self.R * (np.cos(angle) * self.xi + np.sin(angle) * self.eta)


def _corner(B: np.ndarray, M: np.ndarray, E: np.ndarray):
    """The corner at M (section 2.2) from B, M, E [m], shape (3,) each.

    Returns:
        (|BM| [m], |ME| [m], a_hat, d_hat, a_hat x d_hat, sin(angle BME), angle BME [rad]) with
        a = M - B and d = M - E; the angle BME = angle(a_hat, d_hat), in (0, pi).

    Raises:
        ValueError: B or E coinciding with M, or B, M, E collinear (no corner to loop through).
    """
    a = M - B
    d = M - E
    norm_a = float(np.linalg.norm(a))
    norm_d = float(np.linalg.norm(d))
    if norm_a == 0.0:
        raise invalid("B", f"B and M coincide (both {M}): segment BM has no length, no corner")
    if norm_d == 0.0:
        raise invalid("E", f"E and M coincide (both {M}): segment ME has no length, no corner")
    a_hat = a / norm_a
    d_hat = d / norm_d
    cross = np.cross(a_hat, d_hat)
    sin_angle = float(np.linalg.norm(cross))
    cos_angle = float(a_hat @ d_hat)
    if sin_angle < _COLLINEAR_SIN_TOL:
        if cos_angle > 0.0:
            raise ValueError(
                "B, M and E are collinear with B and E on the same side of M (angle BME = 0): "
                "the path reverses at M, there is no corner to loop through"
            )
        raise ValueError(
            "B, M and E are collinear with M between B and E (angle BME = pi): "
            "the path is straight, there is no corner to loop through"
        )
    corner_angle = float(np.arctan2(sin_angle, cos_angle))  # angle BME = angle(a_hat, d_hat)
    return norm_a, norm_d, a_hat, d_hat, cross, sin_angle, corner_angle


def _loop_delta(delta, radius, corner_angle: float, half_sin: float) -> float:
    """Delta [m], the distance from M to the loop centre, from ``delta`` [m] or ``radius`` R [m]
    (section 2.2: Delta = R / sin(angle BME / 2), ``half_sin`` = sin(``corner_angle`` / 2), the
    angle BME [rad]).

    Raises:
        ValueError: neither given, a non-positive or non-finite one, or both given and not
            describing the same loop (to a relative 1e-9).
    """
    if delta is None and radius is None:
        raise ValueError(
            "delta or radius must be given (Delta [m] or R [m] of the loop), got neither"
        )
    if delta is not None:
        delta = positive_scalar(delta, "delta", "m")
    if radius is not None:
        radius = positive_scalar(radius, "radius", "m")
        delta_from_radius = radius / half_sin  # section 2.2: Delta from R and the half angle BME
        if delta is None:
            delta = delta_from_radius
        elif abs(delta - delta_from_radius) > _FIT_RTOL * delta:
            raise ValueError(
                f"radius = {radius} m does not fit delta = {delta} m for the angle BME = "
                f"{corner_angle} rad: the loop tangent to BM and EM with centre at distance delta "
                f"from M has R = delta sin(angle / 2) = {delta * half_sin} m"
            )
    return delta


def loop_geometry(B, M, E, delta=None, radius=None) -> LoopGeometry:
    """Loop path geometry from B, M, E and Delta or R (section 2.2, flowchart of Fig. 3).

    a = M - B and d = M - E; b = a_hat + d_hat is along the bisector of the angle BME and
    O1 = M + Delta b_hat. R is the distance from O1 to the line BM, which is Delta sin(angle/2); the
    tangent points are T1 = M + l a_hat and T2 = M + l d_hat with l = sqrt(Delta^2 - R^2)
    (Pythagoras) = Delta cos(angle/2). The arc angle is beta = pi + angle(a_hat, d_hat) and the
    arc starts at beta_b = pi - beta / 2 (eq. 11). Both R and l are evaluated in the half-angle form
    (same values, no cancellation when the corner is nearly straight).

    Give ``delta`` or ``radius`` (the paper's alternative: Delta = R / sin(angle BME / 2)). Both may
    be given only if they describe the same loop.

    Args:
        B: start point [m], shape (3,).
        M: corner point, passed twice [m], shape (3,).
        E: end point [m], shape (3,).
        delta: Delta, distance from M to the loop centre [m], > 0.
        radius: R, loop radius [m], > 0.

    Returns:
        LoopGeometry.

    Raises:
        ValueError: a point that is not a finite 3-vector; B or E coinciding with M; B, M, E
            collinear (no corner to loop through); neither or a non-positive/non-finite delta or
            radius; delta and radius given together that do not fit the corner.
    """
    B = finite_array(B, "B", "m", shape=(3,))
    M = finite_array(M, "M", "m", shape=(3,))
    E = finite_array(E, "E", "m", shape=(3,))
    norm_a, norm_d, a_hat, d_hat, cross, sin_angle, corner_angle = _corner(B, M, E)
    half_sin = np.sin(0.5 * corner_angle)
    half_cos = np.cos(0.5 * corner_angle)
    delta = _loop_delta(delta, radius, corner_angle, half_sin)

    b = a_hat + d_hat  # bisector direction of the angle BME, away from B and E
    b_hat = _unit(b)
    O1 = M + delta * b_hat
    R = float(delta * half_sin)  # distance from O1 to the line BM (or EM)
    l_tangent = float(delta * half_cos)  # |M T1| = |M T2| = sqrt(Delta^2 - R^2)
    T1 = M + l_tangent * a_hat
    T2 = M + l_tangent * d_hat
    beta = float(np.pi + corner_angle)  # pi + angle between a_hat and d_hat
    beta_b = float(np.pi - 0.5 * beta)  # eq. 11

    # Local frame of eq. 12 (docs/papers.md): xi towards M, zeta normal to the path's plane.
    xi = (M - O1) / delta
    zeta = cross / sin_angle
    eta = np.cross(zeta, xi)

    return LoopGeometry(
        B=_readonly(B),
        M=_readonly(M),
        E=_readonly(E),
        delta=float(delta),
        R=R,
        corner_angle=corner_angle,
        a_hat=_readonly(a_hat),
        d_hat=_readonly(d_hat),
        b_hat=_readonly(b_hat),
        O1=_readonly(O1),
        T1=_readonly(T1),
        T2=_readonly(T2),
        beta=beta,
        beta_b=beta_b,
        xi=_readonly(xi),
        eta=_readonly(eta),
        zeta=_readonly(zeta),
        ds_BM=norm_a,
        ds_MT1=l_tangent,
        ds_arc=float(beta * R),
        ds_T2M=l_tangent,
        ds_ME=norm_d,
    )
