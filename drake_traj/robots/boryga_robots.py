"""The three example manipulators of Boryga ("Trajectory Planning of an End-Effector for
Path with Loop", section 4): kinematics, closed-form inverse kinematics and the loop placement.

Robots (the paper's dimensions; everything else is chosen here and marked so):

* ``anthropomorphic`` (Fig. 8, eq. 15-20): waist theta1 about z, shoulder theta2 and elbow theta3
  about the horizontal axis; lambda1 = 0.33 m (shoulder height), l2 = 0.42 m, l3 = 0.36 m.
* ``scara`` (Fig. 12, eq. 21-26): theta1, theta2 about vertical axes, quill stroke lambda3 down;
  lambda1 = 0.3 m, lambda2 = 0.065 m, l1 = 0.54 m, l2 = 0.42 m.
* ``cartesian`` (Fig. 16, eq. 27-32): lambda1 along z, lambda2 along y, lambda3 along -x;
  l2 = 0.24 m.

Positions are the paper's base frame xyz [m] (the URDFs' ``base`` link, welded to the world); the
point solved for is the URDF frame ``tool0``. Joint vectors are ordered as ``joint_names``
(angles in rad, strokes in m). The paper gives no joint limits or masses: the limits below are the
URDFs' (plausible values chosen for this project), the masses are in the URDFs' comments.

Inverse kinematics, branch and corrections:

* Anthropomorphic, eq. 18-20 as printed, with eq. 18's arctg(s_y / s_x) read as the quadrant-correct
  atan2(s_y, s_x) (the arm reaches forward, l2 c2 + l3 c23 >= 0) and eq. 19's arctg(A / sqrt(B)) as
  atan2(A, sqrt(B)) (the same for B > 0). Branch: theta3 = +arccos in [0, pi], "elbow down": the
  upper arm is below the shoulder-to-tool line by the arcsin term of eq. 19. The arcsin of
  eq. 19 is valid on the whole workspace because l2 > l3 (the angle it stands for never exceeds
  pi / 2). Points on the joint-1 axis (s_x = s_y = 0) are rejected: theta1 is undefined there.
* SCARA, Correction (docs/papers.md): eq. 24-25 as printed are inconsistent (theta2 = -arccos needs theta1 =
  atan2 + arcsin). Used here: theta2 = -arccos((B - D) / C) in [-pi, 0] (eq. 25 as printed) and
  theta1 = atan2(s_y, s_x) + arcsin(sqrt((C^2 - (B - D)^2) / (E^2 B))) (eq. 24 with the sign
  fixed), wrapped to (-pi, pi]. Valid for the whole annulus because l1 > l2.
* Cartesian: eq. 30-32 as printed.

Out-of-reach points raise ValueError naming the point's index and the reason (arccos argument
beyond +-1, negative SCARA stroke, point on the joint-1 axis, joint beyond its limit). Correction (docs/papers.md): the paper's example path (Table 1, z = 1 m) is out of reach of the anthropomorphic arm (0.97 to
1.03 m from the shoulder against a reach of 0.78 m) and needs a negative SCARA stroke, so
:func:`paper_loop_placement` moves it into each workspace (see there).

Plain numpy, vectorised over leading dimensions (positions and joints of shape (..., 3)); the tests
check FK against Drake's MultibodyPlant and IK/joint rates against FK and finite differences.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from drake_traj.errors import SingularConfigurationError
from drake_traj.robots.base import LIMIT_TOL, PointRobot, format_point, joint_vectors, stack_columns

__all__ = [
    "ROBOT_NAMES",
    "AnthropomorphicArm",
    "ScaraArm",
    "CartesianRobot",
]

ROBOT_NAMES = ("anthropomorphic", "scara", "cartesian")

# Slack on the arccos argument (points exactly on the workspace boundary).
_DOMAIN_TOL = 1e-12
# Points closer than this to the anthropomorphic arm's joint-1 axis have no defined theta1 [m].
_AXIS_TOL = 1e-9
# Jacobians with a singularity measure (in [0, 1]) below this are treated as singular.
_SINGULAR_TOL = 1e-9


class _PaperRobot(PointRobot):
    """Boryga's robots: three joints placing a point; adds the rates along a tool motion."""

    data_source: ClassVar[str] = "Boryga, section 4 (dimensions; the manual's papers page); joint limits chosen here (the URDFs)"

    # ---- rates -------------------------------------------------------------------------------
    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """Joint velocity and acceleration from the tool velocity ``v`` and acceleration ``a``.

        qd = J(q)^-1 v and qdd = J(q)^-1 (a - dJ/dt qd). All arrays (..., 3), broadcast together.

        Raises:
            ValueError: J(q) singular at some point (index named).
        """
        q = joint_vectors(q, 3)
        v = joint_vectors(v, 3, "v")
        a = joint_vectors(a, 3, "a")
        shape = np.broadcast_shapes(q.shape, v.shape, a.shape)
        q, v, a = (np.broadcast_to(x, shape).reshape(-1, 3) for x in (q, v, a))
        measure = np.broadcast_to(self.singularity_measure(q), (len(q),))
        singular = np.flatnonzero(measure < _SINGULAR_TOL)
        if singular.size:
            index = int(singular[0])
            raise SingularConfigurationError(
                f"point {index} at q = {format_point(q[index])}: the {self.name} robot's Jacobian is singular "
                f"(singularity measure {measure[index]:.3g}), joint rates are undefined"
            )
        jac = np.broadcast_to(self.jacobian(q), (len(q), 3, 3))
        qd = np.linalg.solve(jac, v[..., None])[..., 0]
        qdd = np.linalg.solve(jac, (a - self.bias(q, qd))[..., None])[..., 0]
        return qd.reshape(shape), qdd.reshape(shape)

    def joint_trajectory(self, plan, times) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) of the tool motion ``plan`` (anything with ``sample(t)`` -> p, v, a, ...).

        Raises:
            ValueError: a sample out of reach (its index and time named) or at a singularity.
        """
        times = np.asarray(times, dtype=float)
        p, v, a = plan.sample(times)[:3]
        q = self.ik(p, label="sample", times=times)
        qd, qdd = self.joint_rates(q, v, a)
        return q, qd, qdd


# ------------------------------------------------------------------------------------------------
# Anthropomorphic arm, Fig. 8, eq. 15-20.
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AnthropomorphicArm(_PaperRobot):
    """Anthropomorphic 3-DOF arm of Boryga (Fig. 8). Lengths [m] are the paper's."""

    name: ClassVar[str] = "anthropomorphic"
    model_file: ClassVar[str] = "boryga_anthropomorphic.urdf"
    joint_names: ClassVar[tuple[str, str, str]] = ("waist_joint", "shoulder_joint", "elbow_joint")
    joint_types: ClassVar[tuple[str, str, str]] = ("revolute", "revolute", "revolute")

    lambda1: float = 0.33  # shoulder height
    l2: float = 0.42  # upper arm
    l3: float = 0.36  # forearm
    # Not in the paper (chosen, = URDF): +-170 deg waist, +-100 deg shoulder, +-150 deg elbow.
    lower: tuple[float, float, float] = (-math.radians(170), -math.radians(100), -math.radians(150))
    upper: tuple[float, float, float] = (math.radians(170), math.radians(100), math.radians(150))
    velocity_limit: tuple[float, float, float] = (3.0, 3.0, 3.5)  # [rad/s]
    effort_limit: tuple[float, float, float] = (150.0, 150.0, 80.0)  # [N m]

    @property
    def reach(self) -> float:
        """Largest distance of the tool from the shoulder (0, 0, lambda1), l2 + l3 [m]."""
        return self.l2 + self.l3

    def _terms(self, q):
        q = joint_vectors(q, 3)
        t1, t2, t3 = q[..., 0], q[..., 1], q[..., 2]
        c1, s1 = np.cos(t1), np.sin(t1)
        c2, s2 = np.cos(t2), np.sin(t2)
        c23, s23 = np.cos(t2 + t3), np.sin(t2 + t3)
        r = self.l2 * c2 + self.l3 * c23  # horizontal distance from the joint-1 axis
        h = self.l2 * s2 + self.l3 * s23  # height above the shoulder
        return c1, s1, c2, s2, c23, s23, r, h

    def fk(self, q) -> np.ndarray:
        """Eq. 15-17: s = (c1 (l2 c2 + l3 c23), s1 (l2 c2 + l3 c23), lambda1 + l2 s2 + l3 s23)."""
        c1, s1, _, _, _, _, r, h = self._terms(q)
        return stack_columns((c1 * r, s1 * r, self.lambda1 + h))

    def jacobian(self, q) -> np.ndarray:
        c1, s1, _, _, c23, s23, r, h = self._terms(q)
        zero = np.zeros_like(r)
        col1 = stack_columns((-s1 * r, c1 * r, zero))
        col2 = stack_columns((-c1 * h, -s1 * h, r))
        col3 = stack_columns((-c1 * self.l3 * s23, -s1 * self.l3 * s23, self.l3 * c23))
        return np.stack((col1, col2, col3), axis=-1)

    def bias(self, q, qd) -> np.ndarray:
        c1, s1, c2, s2, c23, s23, r, _ = self._terms(q)
        qd = joint_vectors(qd, 3, "qd")
        w1, w2 = qd[..., 0], qd[..., 1]
        w23 = qd[..., 1] + qd[..., 2]
        r_dot = -self.l2 * s2 * w2 - self.l3 * s23 * w23
        r_ddot = -self.l2 * c2 * w2**2 - self.l3 * c23 * w23**2  # with qdd = 0
        h_ddot = -self.l2 * s2 * w2**2 - self.l3 * s23 * w23**2
        return stack_columns(
            (
                -c1 * w1**2 * r - 2.0 * s1 * w1 * r_dot + c1 * r_ddot,
                -s1 * w1**2 * r + 2.0 * c1 * w1 * r_dot + s1 * r_ddot,
                h_ddot,
            )
        )

    def singularity_measure(self, q) -> np.ndarray:
        """min(|r| / (l2 + l3), |sin theta3|): det J = -l2 l3 r sin(theta3)."""
        q = joint_vectors(q, 3)
        _, _, _, _, _, _, r, _ = self._terms(q)
        return np.minimum(np.abs(r) / self.reach, np.abs(np.sin(q[..., 2])))

    def _ik_raw(self, p):
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        A = z - self.lambda1
        B = x**2 + y**2
        C = 2.0 * self.l2 * self.l3
        D = self.l2**2 + self.l3**2
        E = 2.0 * self.l2
        rho2 = B + A**2  # squared distance from the shoulder
        arg3 = (rho2 - D) / C  # arccos argument of eq. 20
        problems = []
        for index in np.flatnonzero(arg3 > 1.0 + _DOMAIN_TOL):
            problems.append((int(index), (
                f"distance {math.sqrt(rho2[index]):.6g} m from the shoulder (0, 0, {self.lambda1}) "
                f"exceeds the reach l2 + l3 = {self.reach:.6g} m (arccos argument of eq. 20 = "
                f"{arg3[index]:.6g} > 1)")))
        for index in np.flatnonzero(arg3 < -1.0 - _DOMAIN_TOL):
            problems.append((int(index), (
                f"distance {math.sqrt(rho2[index]):.6g} m from the shoulder is below |l2 - l3| = "
                f"{abs(self.l2 - self.l3):.6g} m (arccos argument of eq. 20 = {arg3[index]:.6g} < -1)")))
        bad_domain = np.abs(arg3) > 1.0 + _DOMAIN_TOL
        on_axis = (np.sqrt(B) < _AXIS_TOL) & ~bad_domain
        for index in np.flatnonzero(on_axis):
            problems.append((int(index), (
                "the point is on the joint-1 axis (s_x = s_y = 0): theta1 of eq. 18 is undefined "
                "(shoulder singularity)")))
        arg3 = np.clip(arg3, -1.0, 1.0)
        theta1 = np.arctan2(y, x)  # eq. 18, quadrant-correct
        theta3 = np.arccos(arg3)  # eq. 20
        # eq. 19: arctg(A / sqrt(B)) - arcsin(sqrt((C^2 - (B + A^2 - D)^2) / (E^2 (B + A^2))))
        with np.errstate(divide="ignore", invalid="ignore"):
            inner = (C**2 - (rho2 - D) ** 2) / (E**2 * rho2)
        theta2 = np.arctan2(A, np.sqrt(B)) - np.arcsin(np.sqrt(np.clip(inner, 0.0, 1.0)))
        q = np.stack((theta1, theta2, theta3), axis=-1)
        q[bad_domain | on_axis] = np.nan
        return q, problems


# ------------------------------------------------------------------------------------------------
# SCARA, Fig. 12, eq. 21-26 (Corrected (docs/papers.md): eq. 24 sign).
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ScaraArm(_PaperRobot):
    """SCARA of Boryga (Fig. 12). Lengths [m] are the paper's; q = (theta1, theta2, lambda3)."""

    name: ClassVar[str] = "scara"
    model_file: ClassVar[str] = "boryga_scara.urdf"
    joint_names: ClassVar[tuple[str, str, str]] = ("shoulder_joint", "elbow_joint", "quill_joint")
    joint_types: ClassVar[tuple[str, str, str]] = ("revolute", "revolute", "prismatic")

    lambda1: float = 0.3  # column height (joint 1)
    lambda2: float = 0.065  # height of arm 2 above arm 1
    l1: float = 0.54
    l2: float = 0.42
    # Not in the paper (chosen, = URDF): +-170 deg, +-150 deg, stroke 0 to 0.2 m.
    lower: tuple[float, float, float] = (-math.radians(170), -math.radians(150), 0.0)
    upper: tuple[float, float, float] = (math.radians(170), math.radians(150), 0.2)
    velocity_limit: tuple[float, float, float] = (3.0, 5.0, 1.0)  # [rad/s, rad/s, m/s]
    effort_limit: tuple[float, float, float] = (150.0, 80.0, 200.0)  # [N m, N m, N]

    @property
    def top(self) -> float:
        """Tool height at zero stroke, lambda1 + lambda2 [m] (the highest reachable z)."""
        return self.lambda1 + self.lambda2

    def fk(self, q) -> np.ndarray:
        """Eq. 21-23: s = (l1 c1 + l2 c12, l1 s1 + l2 s12, lambda1 + lambda2 - lambda3)."""
        q = joint_vectors(q, 3)
        t1, t12 = q[..., 0], q[..., 0] + q[..., 1]
        return stack_columns(
            (
                self.l1 * np.cos(t1) + self.l2 * np.cos(t12),
                self.l1 * np.sin(t1) + self.l2 * np.sin(t12),
                self.top - q[..., 2],
            )
        )

    def jacobian(self, q) -> np.ndarray:
        q = joint_vectors(q, 3)
        t1, t12 = q[..., 0], q[..., 0] + q[..., 1]
        c1, s1, c12, s12 = np.cos(t1), np.sin(t1), np.cos(t12), np.sin(t12)
        zero = np.zeros_like(t1)
        col1 = stack_columns((-self.l1 * s1 - self.l2 * s12, self.l1 * c1 + self.l2 * c12, zero))
        col2 = stack_columns((-self.l2 * s12, self.l2 * c12, zero))
        col3 = stack_columns((zero, zero, zero - 1.0))
        return np.stack((col1, col2, col3), axis=-1)

    def bias(self, q, qd) -> np.ndarray:
        q = joint_vectors(q, 3)
        qd = joint_vectors(qd, 3, "qd")
        t1, t12 = q[..., 0], q[..., 0] + q[..., 1]
        w1, w12 = qd[..., 0], qd[..., 0] + qd[..., 1]
        return stack_columns(
            (
                -self.l1 * np.cos(t1) * w1**2 - self.l2 * np.cos(t12) * w12**2,
                -self.l1 * np.sin(t1) * w1**2 - self.l2 * np.sin(t12) * w12**2,
                np.zeros_like(t1),
            )
        )

    def singularity_measure(self, q) -> np.ndarray:
        """|sin theta2|: det J = -l1 l2 sin(theta2) (arm stretched or folded)."""
        return np.abs(np.sin(joint_vectors(q, 3)[..., 1]))

    def _ik_raw(self, p):
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        B = x**2 + y**2
        C = 2.0 * self.l1 * self.l2
        D = self.l1**2 + self.l2**2
        E = 2.0 * self.l1
        arg2 = (B - D) / C  # arccos argument of eq. 25
        stroke = self.top - z  # eq. 26
        problems = []
        for index in np.flatnonzero(arg2 > 1.0 + _DOMAIN_TOL):
            problems.append((int(index), (
                f"horizontal distance {math.sqrt(B[index]):.6g} m from the joint-1 axis exceeds "
                f"l1 + l2 = {self.l1 + self.l2:.6g} m (arccos argument of eq. 25 = {arg2[index]:.6g} > 1)")))
        for index in np.flatnonzero(arg2 < -1.0 - _DOMAIN_TOL):
            problems.append((int(index), (
                f"horizontal distance {math.sqrt(B[index]):.6g} m from the joint-1 axis is below "
                f"|l1 - l2| = {abs(self.l1 - self.l2):.6g} m (arccos argument of eq. 25 = "
                f"{arg2[index]:.6g} < -1)")))
        bad_domain = np.abs(arg2) > 1.0 + _DOMAIN_TOL
        negative = (stroke < -LIMIT_TOL) & ~bad_domain
        for index in np.flatnonzero(negative):
            problems.append((int(index), (
                f"negative stroke lambda3 = {stroke[index]:.6g} m (eq. 26): s_z = {z[index]:.6g} m is "
                f"above the top of the stroke lambda1 + lambda2 = {self.top:.6g} m")))
        arg2 = np.clip(arg2, -1.0, 1.0)
        theta2 = -np.arccos(arg2)  # eq. 25 as printed
        with np.errstate(divide="ignore", invalid="ignore"):
            inner = (C**2 - (B - D) ** 2) / (E**2 * B)
        # eq. 24 with the docs/papers.md sign: + arcsin goes with theta2 = -arccos.
        theta1 = np.arctan2(y, x) + np.arcsin(np.sqrt(np.clip(inner, 0.0, 1.0)))
        theta1 = np.pi - np.mod(np.pi - theta1, 2.0 * np.pi)  # wrap to (-pi, pi]
        q = np.stack((theta1, theta2, stroke), axis=-1)
        q[bad_domain | negative] = np.nan
        return q, problems


# ------------------------------------------------------------------------------------------------
# Cartesian robot, Fig. 16, eq. 27-32.
# ------------------------------------------------------------------------------------------------

_CARTESIAN_J = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


@dataclass(frozen=True)
class CartesianRobot(_PaperRobot):
    """Cartesian robot of Boryga (Fig. 16); q = (lambda1, lambda2, lambda3) [m]."""

    name: ClassVar[str] = "cartesian"
    model_file: ClassVar[str] = "boryga_cartesian.urdf"
    joint_names: ClassVar[tuple[str, str, str]] = ("z_joint", "y_joint", "x_joint")
    joint_types: ClassVar[tuple[str, str, str]] = ("prismatic", "prismatic", "prismatic")

    l2: float = 0.24
    # Not in the paper (chosen, = URDF): lambda1 0 to 1 m, lambda2 and lambda3 -0.8 to 0.8 m.
    lower: tuple[float, float, float] = (0.0, -0.8, -0.8)
    upper: tuple[float, float, float] = (1.0, 0.8, 0.8)
    velocity_limit: tuple[float, float, float] = (1.0, 1.0, 1.0)  # [m/s]
    effort_limit: tuple[float, float, float] = (600.0, 300.0, 300.0)  # [N]

    def fk(self, q) -> np.ndarray:
        """Eq. 27-29: s = (-lambda3, lambda2, lambda1 + l2)."""
        q = joint_vectors(q, 3)
        return stack_columns((-q[..., 2], q[..., 1], q[..., 0] + self.l2))

    def jacobian(self, q) -> np.ndarray:
        q = joint_vectors(q, 3)
        return np.broadcast_to(_CARTESIAN_J, q.shape[:-1] + (3, 3)).copy()

    def bias(self, q, qd) -> np.ndarray:
        return np.zeros(np.broadcast_shapes(joint_vectors(q, 3).shape, joint_vectors(qd, 3, "qd").shape))

    def singularity_measure(self, q) -> np.ndarray:
        return np.ones(joint_vectors(q, 3).shape[:-1])

    def _ik_raw(self, p):
        # eq. 30-32; only the joint ranges can put a point out of reach.
        return np.stack((p[:, 2] - self.l2, p[:, 1], -p[:, 0]), axis=-1), []
