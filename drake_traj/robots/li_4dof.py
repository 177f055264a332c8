"""The 4-DOF serial collaborative robot of Li et al. 2019 (Li, Zhang, Zhou, "Trajectory Planning of
High Precision Collaborative Robots", section 4, Fig. 5, Tables 3-5, Fig. 6): kinematics, inverse
kinematics for the paper's planar task, joint limits and the closed test path.

Standard DH table (Table 3), T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), lengths in metres
(the paper's mm / 1000). OCR corrections (docs/papers.md): "057" is 0.5 pi.

    i   d_i     a_i     alpha_i   theta_i
    1   0.255   0       pi/2      q1
    2   0       0.257   0         q2 + pi/2
    3   0       0.250   0         q3 - pi/2
    4   0       0.140   0         q4 - pi/2

Joint limits (Table 5; the text calls it "Tab. 4", docs/papers.md). OCR corrections: "0.757" is 0.75 pi,
"0.257" is 0.25 pi, "1.257" is 1.25 pi, "25" is 2.5, "15" is 1.5:

    joint   range [rad]              max velocity [rad/s]   max acceleration [rad/s^2]
    1       [-0.75 pi, 0.75 pi]      2.0                    1.0
    2       [-0.75 pi, 0.75 pi]      2.5                    1.2
    3       [-0.25 pi, 1.25 pi]      3.0                    1.5
    4       [-0.25 pi, 1.25 pi]      3.0                    1.8

The tool limits of Table 4 (200 mm/s, 100 mm/s^2) belong to the paper's task and live with the
planner (:mod:`drake_traj.planners.li`).

Geometry. Joint 1 turns about the vertical base z axis; joints 2, 3, 4 are parallel horizontal
axes, so the arm is a planar 3R chain (257, 250, 140 mm) in the vertical plane at azimuth q1, with
the shoulder d1 = 0.255 m above the base plane Z = 0. In that plane, with u the horizontal distance
from the joint-1 axis and w the height (see :meth:`Li4Dof.fk`):

    u = -L2 sin q2 + L3 cos(q2 + q3) + L4 sin(q2 + q3 + q4)
    w = d1 + L2 cos q2 + L3 sin(q2 + q3) - L4 cos(q2 + q3 + q4)
    p = (u cos q1, u sin q1, w)

At q = 0 (the paper's initial pose) the upper arm is vertical, the forearm horizontal and the last
link points straight down: ``tool0`` is at (0.25, 0, 0.372) m.

Inverse kinematics (the paper's task: a point path in the XY plane at Z = 0; the tool point has
3 coordinates, the arm 4 joints, so one joint is redundant). Chosen here and used everywhere:

* The last link's pitch phi = q2 + q3 + q4 is held at ``tool_pitch`` (default 0: the last link,
  i.e. the pen of the paper's experiment, points straight down, as at q = 0). So q4 = phi - q2 - q3
  and joint 4 only keeps the pen vertical; joints 1-3 place the point.
* q1 = atan2(y, x): the arm reaches forward (u > 0). Points on the joint-1 axis are rejected.
* Elbow up: q3 = pi/2 - arccos(c) in [-pi/2, pi/2] (the branch of q = 0, the forearm turned
  downwards from the upper arm), c = (rho^2 - L2^2 - L3^2) / (2 L2 L3), rho the distance of the
  wrist (joint 4) from the shoulder. q2 = atan2(w_w, u_w) - atan2(L3 sin psi, L2 + L3 cos psi)
  - pi/2 with psi = q3 - pi/2, wrapped to (-pi, pi].

Joint rates use the same redundancy resolution: [J; 0 1 1 1] qd = [v; 0] (the pitch stays
constant), and likewise for qdd. Out-of-reach points raise ValueError naming the point's index and
the reason (wrist beyond L2 + L3 or closer than |L2 - L3| to the shoulder, point on the joint-1
axis, joint beyond its limit). With the pen vertical and q3 >= -0.25 pi, the nearest reachable point
of the plane Z = 0 is 0.1564 m from the joint-1 axis, the farthest 0.4938 m.

Plain numpy, vectorised over leading dimensions (positions (..., 3), joints (..., 4)); the tests
check FK against Drake's MultibodyPlant (models/li_4dof.urdf) and IK / joint rates against FK and
finite differences.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from drake_traj.errors import SingularConfigurationError
from drake_traj.robots.base import PointRobot, format_point, joint_vectors, point_array, stack_columns

__all__ = ["Li4Dof", "LI_4DOF"]

_HALF_PI = 0.5 * math.pi
_DOMAIN_TOL = 1e-12  # slack on the arccos argument (points exactly on the workspace boundary)
_AXIS_TOL = 1e-9  # points closer than this to the joint-1 axis have no defined q1 [m]
_SINGULAR_TOL = 1e-9  # singularity measure below this: J singular

NUM_JOINTS = 4


def _wrap(angle):
    """Wrap to (-pi, pi]."""
    return np.pi - np.mod(np.pi - angle, 2.0 * np.pi)


@dataclass(frozen=True)
class Li4Dof(PointRobot):
    """The 4-DOF collaborative robot of Li et al. 2019 (Fig. 5). DH values (Table 3) in m and rad.

    Attributes:
        d, a, alpha, theta_offset: the standard DH table; theta_i = q_i + theta_offset_i.
        lower, upper: joint ranges [rad] (Table 5).
        velocity_limit: max joint speeds [rad/s] (Table 5).
        acceleration_limit: max joint accelerations [rad/s^2] (Table 5).
        effort_limit: [N m], NOT in the paper (chosen, = URDF).
        tool_pitch: q2 + q3 + q4 held by :meth:`ik` and :meth:`joint_rates` [rad]; 0 = the last
            link points straight down (chosen, see the module docstring).
    """

    name: ClassVar[str] = "li_4dof"
    model_file: ClassVar[str] = "li_4dof.urdf"
    data_source: ClassVar[str] = "Li et al. 2019, Tables 3 and 5 (DH table, joint ranges and limits; the manual's papers page)"
    joint_names: ClassVar[tuple[str, ...]] = ("joint1", "joint2", "joint3", "joint4")
    joint_types: ClassVar[tuple[str, ...]] = ("revolute",) * 4
    base_frame: ClassVar[str] = "base"
    tool_frame: ClassVar[str] = "tool0"

    d: tuple[float, float, float, float] = (0.255, 0.0, 0.0, 0.0)
    a: tuple[float, float, float, float] = (0.0, 0.257, 0.250, 0.140)
    alpha: tuple[float, float, float, float] = (_HALF_PI, 0.0, 0.0, 0.0)
    theta_offset: tuple[float, float, float, float] = (0.0, _HALF_PI, -_HALF_PI, -_HALF_PI)
    lower: tuple[float, float, float, float] = (-0.75 * math.pi, -0.75 * math.pi, -0.25 * math.pi,
                                                -0.25 * math.pi)
    upper: tuple[float, float, float, float] = (0.75 * math.pi, 0.75 * math.pi, 1.25 * math.pi,
                                                1.25 * math.pi)
    velocity_limit: tuple[float, float, float, float] = (2.0, 2.5, 3.0, 3.0)
    acceleration_limit: tuple[float, float, float, float] = (1.0, 1.2, 1.5, 1.8)
    effort_limit: tuple[float, float, float, float] = (40.0, 60.0, 30.0, 10.0)
    tool_pitch: float = 0.0

    # ---- dimensions ----------------------------------------------------------------------------
    @property
    def d1(self) -> float:
        """Shoulder height above the base plane [m]."""
        return self.d[0]

    @property
    def lengths(self) -> tuple[float, float, float]:
        """(L2, L3, L4) = (a2, a3, a4) [m]: upper arm, forearm, last link."""
        return self.a[1], self.a[2], self.a[3]

    @property
    def reach(self) -> float:
        """L2 + L3 + L4 [m], the largest distance of tool0 from the shoulder."""
        return float(sum(self.lengths))

    # ---- limits --------------------------------------------------------------------------------
    @property
    def acceleration_limits(self) -> np.ndarray:
        return np.array(self.acceleration_limit, dtype=float)

    @property
    def joint_move_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Table 5's joint velocity and acceleration limits."""
        return self.velocity_limits, self.acceleration_limits

    @property
    def home_configuration(self) -> np.ndarray:
        """q = 0, the paper's initial pose."""
        return np.zeros(NUM_JOINTS)

    def fk_pose(self, q) -> np.ndarray:
        """Homogeneous transform of DH frame 4 (= URDF ``tool0``) in the base, shape (..., 4, 4).

        The plain product of the four standard DH matrices of Table 3.
        """
        q = joint_vectors(q, NUM_JOINTS)
        pose = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4)).copy()
        for i in range(NUM_JOINTS):
            theta = q[..., i] + self.theta_offset[i]
            ct, st = np.cos(theta), np.sin(theta)
            ca, sa = math.cos(self.alpha[i]), math.sin(self.alpha[i])
            step = np.zeros(q.shape[:-1] + (4, 4))
            step[..., 0, 0], step[..., 0, 1], step[..., 0, 2] = ct, -st * ca, st * sa
            step[..., 1, 0], step[..., 1, 1], step[..., 1, 2] = st, ct * ca, -ct * sa
            step[..., 2, 1], step[..., 2, 2] = sa, ca
            step[..., 0, 3], step[..., 1, 3], step[..., 2, 3] = self.a[i] * ct, self.a[i] * st, self.d[i]
            step[..., 3, 3] = 1.0
            pose = pose @ step
        return pose

    def _planar(self, q):
        """Cumulative planar angles and the (u, w) terms of the arm plane."""
        q = joint_vectors(q, NUM_JOINTS)
        l2, l3, l4 = self.lengths
        phi2 = q[..., 1]
        phi3 = phi2 + q[..., 2]
        phi4 = phi3 + q[..., 3]
        s2, c2 = np.sin(phi2), np.cos(phi2)
        s3, c3 = np.sin(phi3), np.cos(phi3)
        s4, c4 = np.sin(phi4), np.cos(phi4)
        u = -l2 * s2 + l3 * c3 + l4 * s4
        w = self.d1 + l2 * c2 + l3 * s3 - l4 * c4
        return q, (s2, c2, s3, c3, s4, c4), u, w

    def fk(self, q) -> np.ndarray:
        """Position of ``tool0`` in the base frame [m], shape (..., 3) (= fk_pose(q)[..., :3, 3])."""
        q, _, u, w = self._planar(q)
        return stack_columns((u * np.cos(q[..., 0]), u * np.sin(q[..., 0]), w))

    def pitch(self, q) -> np.ndarray:
        """q2 + q3 + q4: the last link's angle from straight down in the arm plane [rad]."""
        q = joint_vectors(q, NUM_JOINTS)
        return q[..., 1] + q[..., 2] + q[..., 3]

    def jacobian(self, q) -> np.ndarray:
        """J(q) = d fk / dq, shape (..., 3, 4)."""
        q, (s2, c2, s3, c3, s4, c4), u, _ = self._planar(q)
        l2, l3, l4 = self.lengths
        c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
        # d(u, w)/d q_k for k = 2, 3, 4 (phi_j depends on q_k for j >= k).
        du4, dw4 = l4 * c4, l4 * s4
        du3, dw3 = du4 - l3 * s3, dw4 + l3 * c3
        du2, dw2 = du3 - l2 * c2, dw3 - l2 * s2
        zero = np.zeros_like(u)
        cols = [stack_columns((-s1 * u, c1 * u, zero))]
        for du, dw in ((du2, dw2), (du3, dw3), (du4, dw4)):
            cols.append(stack_columns((c1 * du, s1 * du, dw)))
        return np.stack(cols, axis=-1)

    def task_jacobian(self, q) -> np.ndarray:
        """[J(q); 0 1 1 1], shape (..., 4, 4): position and the pitch q2 + q3 + q4."""
        jac = self.jacobian(q)
        row = np.broadcast_to(np.array([0.0, 1.0, 1.0, 1.0]), jac.shape[:-2] + (1, 4))
        return np.concatenate([jac, row], axis=-2)

    def bias(self, q, qd) -> np.ndarray:
        """dJ/dt(q, qd) qd: the tool acceleration when qdd = 0 [m/s^2], shape (..., 3)."""
        q, (s2, c2, s3, c3, s4, c4), u, _ = self._planar(q)
        qd = joint_vectors(qd, NUM_JOINTS, "qd")
        l2, l3, l4 = self.lengths
        c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
        w1 = qd[..., 0]
        w2 = qd[..., 1]
        w3 = w2 + qd[..., 2]
        w4 = w3 + qd[..., 3]
        u_dot = -l2 * c2 * w2 - l3 * s3 * w3 + l4 * c4 * w4
        u_ddot = l2 * s2 * w2**2 - l3 * c3 * w3**2 - l4 * s4 * w4**2
        w_ddot = -l2 * c2 * w2**2 - l3 * s3 * w3**2 + l4 * c4 * w4**2
        return stack_columns(
            (
                -c1 * w1**2 * u - 2.0 * s1 * w1 * u_dot + c1 * u_ddot,
                -s1 * w1**2 * u + 2.0 * c1 * w1 * u_dot + s1 * u_ddot,
                w_ddot,
            )
        )

    def singularity_measure(self, q) -> np.ndarray:
        """min(|u| / reach, |cos q3|), in [0, 1]; zero exactly where [J; 0 1 1 1] is singular.

        det [J; 0 1 1 1] = +-u L2 L3 cos(q3): tool on the joint-1 axis (u = 0) or upper arm and
        forearm aligned (q3 = pi/2 stretched, -pi/2 folded).
        """
        q, _, u, _ = self._planar(q)
        return np.minimum(np.abs(u) / self.reach, np.abs(np.cos(q[..., 2])))

    # ---- inverse kinematics ----------------------------------------------------------------------
    def _ik_raw(self, p: np.ndarray):
        """(q, problems): IK of (N, 3) points, NaN rows where there is no solution, and a list of
        (index, reason) for the domain errors."""
        l2, l3, l4 = self.lengths
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        r = np.hypot(x, y)
        phi = self.tool_pitch
        # Wrist (joint 4) relative to the shoulder, in the arm plane.
        uw = r - l4 * math.sin(phi)
        ww = z + l4 * math.cos(phi) - self.d1
        rho2 = uw**2 + ww**2
        arg = (rho2 - l2**2 - l3**2) / (2.0 * l2 * l3)
        problems = []
        for index in np.flatnonzero(arg > 1.0 + _DOMAIN_TOL):
            problems.append((int(index), (
                f"the wrist (joint 4, pitch {phi:.6g} rad) would be {math.sqrt(rho2[index]):.6g} m from "
                f"the shoulder (0, 0, {self.d1}), beyond L2 + L3 = {l2 + l3:.6g} m "
                f"(arccos argument {arg[index]:.6g} > 1)")))
        for index in np.flatnonzero(arg < -1.0 - _DOMAIN_TOL):
            problems.append((int(index), (
                f"the wrist (joint 4, pitch {phi:.6g} rad) would be {math.sqrt(rho2[index]):.6g} m from "
                f"the shoulder, below |L2 - L3| = {abs(l2 - l3):.6g} m (arccos argument "
                f"{arg[index]:.6g} < -1)")))
        bad_domain = np.abs(arg) > 1.0 + _DOMAIN_TOL
        on_axis = (r < _AXIS_TOL) & ~bad_domain
        for index in np.flatnonzero(on_axis):
            problems.append((int(index), (
                "the point is on the joint-1 axis (x = y = 0): q1 is undefined (shoulder singularity)")))
        q1 = np.arctan2(y, x)
        psi = -np.arccos(np.clip(arg, -1.0, 1.0))  # elbow up: forearm turned down from the upper arm
        q3 = _HALF_PI + psi
        upper_arm = np.arctan2(ww, uw) - np.arctan2(l3 * np.sin(psi), l2 + l3 * np.cos(psi))
        q2 = _wrap(upper_arm - _HALF_PI)
        q4 = phi - q2 - q3
        q = np.stack((q1, q2, q3, q4), axis=-1)
        q[bad_domain | on_axis] = np.nan
        return q, problems

    # ---- rates ---------------------------------------------------------------------------------
    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """Joint velocity and acceleration from the tool velocity ``v`` and acceleration ``a``.

        The pitch q2 + q3 + q4 is held constant (the redundancy resolution of :meth:`ik`):
        [J; 0 1 1 1] qd = [v; 0] and [J; 0 1 1 1] qdd = [a - dJ/dt qd; 0].

        Args:
            q: joints (..., 4); v, a: tool velocity and acceleration (..., 3); broadcast together.

        Returns:
            (qd, qdd), each (..., 4).

        Raises:
            ValueError: the Jacobian singular at some point (index named).
        """
        q = joint_vectors(q, NUM_JOINTS)
        v = point_array(v)
        a = point_array(a)
        lead = np.broadcast_shapes(q.shape[:-1], v.shape[:-1], a.shape[:-1])
        q = np.broadcast_to(q, lead + (4,)).reshape(-1, 4)
        v = np.broadcast_to(v, lead + (3,)).reshape(-1, 3)
        a = np.broadcast_to(a, lead + (3,)).reshape(-1, 3)
        measure = self.singularity_measure(q)
        singular = np.flatnonzero(measure < _SINGULAR_TOL)
        if singular.size:
            index = int(singular[0])
            raise SingularConfigurationError(
                f"point {index} at q = {format_point(q[index])}: the {self.name} robot's Jacobian is singular "
                f"(singularity measure {measure[index]:.3g}), joint rates are undefined"
            )
        jac = self.task_jacobian(q)
        zero = np.zeros((len(q), 1))
        qd = np.linalg.solve(jac, np.concatenate([v, zero], axis=1)[..., None])[..., 0]
        rhs = np.concatenate([a - self.bias(q, qd), zero], axis=1)
        qdd = np.linalg.solve(jac, rhs[..., None])[..., 0]
        return qd.reshape(lead + (4,)), qdd.reshape(lead + (4,))


LI_4DOF = Li4Dof()
