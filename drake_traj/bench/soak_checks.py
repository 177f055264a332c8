"""The soak's checks of a plan, written for the soak and independent of the planners' code: the
limits at dense samples and at the pieces' exact peaks, the joint ranges, the goal by Drake's
forward kinematics, the clearance by SceneGraph along the whole motion, and the diagnosis of a
refusal.

- **Limits** (:func:`rate_peaks`, :func:`dense_rates`): the plan is Drake's PiecewisePolynomial
  (each piece a polynomial in the time since its start); the peak of |q̇|, |q̈| and |q⃛| on every
  piece is the largest of its value at the two ends and at the real roots of the next derivative
  inside the piece (companion-matrix eigenvalues, every piece at once). At the 0.1 ms samples, q
  is Drake's own evaluation of the plan (the coefficients must give it back to 1e-9) and its
  derivatives are the pieces' (Horner's rule).
- **Clearance** (:class:`ClearanceCheck`): SceneGraph's signed distances (a cell check's plant of
  its own, :class:`~drake_traj.bench.free_suite.ClearanceProbe`) at samples of the plan, refined
  where the distance could fall below the bound between two samples. A point of the arm moves at
  most ``Σ_j R_j |Δq_j|`` (R_j: the farthest collision geometry outboard of joint j from its
  origin, summed along the chain from its own model, :func:`axis_reach`), so two bodies' distance
  changes by at most twice that; an interval whose ends are d_a and d_b apart keeps at least
  (d_a + d_b)/2 - Σ_j R_j TV_j (TV_j: joint j's travel over the interval, on the 0.1 ms samples).
  Intervals that do not certify the bound are halved down to one millisecond; the samples at
  their ends are then the check.
- **Tool limits** (Li et al. 2019's, :func:`tool_rates`): the TCP's speed and acceleration by
  Drake's Jacobian and bias acceleration at every millisecond of the plan.
- **Refusals** (:func:`diagnose`): a collision refusal's configuration is closer than the
  clearance by the same SceneGraph query; a joint-range refusal's joint is past its range; an
  unreachable pose (:class:`~drake_traj.errors.UnreachablePoseError`) is one Drake's
  InverseKinematics does not reach within the joint ranges from :data:`IK_STARTS` seeded starts
  (:func:`reach_diagnosis`); others are counted by cause without a diagnosis.

Units: rad, rad/s, rad/s², rad/s³, m, s.
"""

import numpy as np
from pydrake.math import RollPitchYaw, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.solvers import IpoptSolver, SnoptSolver, Solve, SolverOptions

from drake_traj.bench.free_suite import ClearanceProbe
from drake_traj.cell import shape_radius
from drake_traj.errors import UnreachablePoseError, in_chain

__all__ = ["ClearanceCheck", "LIMIT_TOLERANCE", "axis_reach", "dense_rates", "diagnose", "piece_coefficients", "pose_error",
           "rate_peaks", "reach_diagnosis", "rotation_angle", "tool_rates"]

DENSE_PERIOD = 1e-4  # [s] between two samples of the limits' check
CLEARANCE_PERIOD = 1e-3  # [s] the finest interval the clearance check halves to
COARSE_STEPS = 64  # clearance samples every 64 ms first
LIMIT_TOLERANCE = 1e-6  # relative: a peak up to (1 + 1e-6) times its limit is within it (round-off)
BORDERLINE = 1e-3  # [m] a collision refusal SceneGraph puts this little beyond the clearance is borderline, not wrong
QUERY_WITHIN = 0.15  # [m] SceneGraph's distances are asked up to this (a farther pair reads as 0.15)
IK_STARTS = 32  # seeded starts of Drake's InverseKinematics for an unreachable pose
IK_REACHED = 1e-9  # [m] and [rad]: a flange pose Drake's solution takes this closely is reached
IK_NEAR = 1e-5  # [m] and [rad]: one it takes this closely only is on the edge of the reach
_IK_OPTIONS = SolverOptions()
_IK_OPTIONS.SetOption(SnoptSolver().solver_id(), "Major optimality tolerance", 1e-12)
_IK_OPTIONS.SetOption(IpoptSolver().solver_id(), "tol", 1e-12)


def piece_coefficients(trajectory) -> tuple[np.ndarray, np.ndarray]:
    """(breaks (K + 1,) [s], coefficients (K, P, n)) of Drake's PiecewisePolynomial ``trajectory``
    (n x 1): q_j(t) = Σ_i coefficients[k, i, j] (t - breaks[k])^i on piece k."""
    count, rows = trajectory.get_number_of_segments(), trajectory.rows()
    pieces = [[trajectory.getPolynomial(k, j, 0).GetCoefficients() for j in range(rows)] for k in range(count)]
    degree = max(len(c) for piece in pieces for c in piece)
    coefficients = np.zeros((count, degree, rows))
    for k, piece in enumerate(pieces):
        for j, c in enumerate(piece):
            coefficients[k, : len(c), j] = c
    return np.asarray(trajectory.get_segment_times()), coefficients


def _derivative(coefficients) -> np.ndarray:
    """The coefficients (K, P - 1, n) of the derivative of each piece."""
    powers = np.arange(1, coefficients.shape[1])[None, :, None]
    return coefficients[:, 1:, :] * powers


def _evaluate(coefficients, x) -> np.ndarray:
    """Σ_i coefficients[..., i] x^i by Horner, coefficients (M, P), x (M, R) -> (M, R)."""
    value = np.zeros(x.shape)
    for i in reversed(range(coefficients.shape[1])):
        value = value * x + coefficients[:, i, None]
    return value


def _real_roots_inside(coefficients, length) -> np.ndarray:
    """Real roots in [0, length_m] of each polynomial (M, P) (NaN padded, (M, P - 1)), every
    polynomial's by the eigenvalues of its companion matrix, grouped by degree."""
    count, size = coefficients.shape
    roots = np.full((count, max(size - 1, 1)), np.nan)
    scale = np.max(np.abs(coefficients), axis=1)
    degree = np.zeros(count, dtype=int)
    for i in range(1, size):  # the highest power whose coefficient is not round-off
        degree[np.abs(coefficients[:, i]) > 1e-13 * scale] = i
    for d in range(1, size):
        rows = np.flatnonzero(degree == d)
        if not len(rows):
            continue
        monic = coefficients[rows, :d] / coefficients[rows, d, None]
        companion = np.zeros((len(rows), d, d))
        companion[:, 1:, :-1] = np.eye(d - 1)
        companion[:, :, -1] = -monic
        eigen = np.linalg.eigvals(companion)
        real = np.abs(eigen.imag) <= 1e-9 * (1 + np.abs(eigen.real))
        inside = real & (eigen.real >= 0) & (eigen.real <= length[rows, None])
        roots[rows, :d] = np.where(inside, eigen.real, np.nan)
    return roots


def rate_peaks(breaks, coefficients, order: int) -> np.ndarray:
    """The exact peak of |d^order q / dt^order| per piece and joint, (K, n): the largest of its
    values at the piece's ends and at the real roots of the next derivative inside the piece."""
    for _ in range(order):
        coefficients = _derivative(coefficients)
    count, size, joints = coefficients.shape
    length = np.repeat(np.diff(breaks), joints)
    flat = coefficients.transpose(0, 2, 1).reshape(count * joints, size)
    if size == 0:
        return np.zeros((count, joints))
    slope = _derivative(flat[:, :, None])[:, :, 0] if size > 1 else np.zeros((len(flat), 1))
    roots = _real_roots_inside(slope, length) if size > 1 else np.full((len(flat), 1), np.nan)
    x = np.concatenate([np.zeros((len(flat), 1)), length[:, None], np.nan_to_num(roots, nan=0.0)], axis=1)
    return np.max(np.abs(_evaluate(flat, x)), axis=1).reshape(count, joints)


def dense_rates(trajectory, period: float = DENSE_PERIOD, pieces=None) -> tuple[np.ndarray, list[np.ndarray]]:
    """(times (N,), [q, q̇, q̈, q⃛] each (N, n)) of ``trajectory`` at every ``period`` [s] and its end:
    q by Drake's evaluation of the plan, its derivatives from the pieces' coefficients
    (:func:`piece_coefficients`, or ``pieces`` already read); ValueError where the coefficients'
    q and Drake's differ by more than 1e-9 (the pieces were misread)."""
    breaks, coefficients = piece_coefficients(trajectory) if pieces is None else pieces
    times = np.append(np.arange(trajectory.start_time(), trajectory.end_time(), period), trajectory.end_time())
    index = np.clip(np.searchsorted(breaks, times, side="right") - 1, 0, len(breaks) - 2)
    local = (times - breaks[index])[:, None]
    values = [trajectory.vector_values(times).T]
    derivative = coefficients  # the pieces' derivative of the order below
    for order in range(4):
        rows = derivative[index]  # (N, P, n): each sample's piece
        value = np.zeros((len(times), coefficients.shape[2]))
        for i in reversed(range(rows.shape[1])):
            value = value * local + rows[:, i, :]
        if order == 0:
            misread = float(np.max(np.abs(value - values[0]), initial=0.0))
            if not misread <= 1e-9 * (1 + float(np.max(np.abs(values[0]), initial=0.0))):
                raise ValueError(f"the plan's pieces read back {misread:.3g} from Drake's evaluation of it")
        else:
            values.append(value)
        derivative = _derivative(derivative)
    return times, values


def axis_reach(checker, joint_names) -> np.ndarray:
    """R_j [m] per revolute joint of the arm in the cell check ``checker``'s plant: a bound on
    the distance from joint j's origin (on its axis) of any collision geometry on its child link,
    on bodies welded to it, and on the links beyond (their offsets summed along the chain).
    ValueError for a prismatic joint."""
    plant, inspector = checker.plant, checker.scene_graph.model_inspector()
    context = plant.CreateDefaultContext()
    joints = [plant.GetJointByName(name, checker.instance) for name in joint_names]
    if any(joint.type_name() != "revolute" for joint in joints):
        raise ValueError("the soak's clearance check takes revolute joints only")
    origins = [joint.frame_on_child().CalcPoseInWorld(context) for joint in joints]
    extent = np.zeros(len(joints))  # the farthest geometry of link j (and what is welded to it) from joint j
    for j, joint in enumerate(joints):
        for body in plant.GetBodiesWeldedTo(joint.child_body()):
            X_OB = origins[j].InvertAndCompose(body.body_frame().CalcPoseInWorld(context))
            for geometry in plant.GetCollisionGeometriesForBody(body):
                X_OG = X_OB @ inspector.GetPoseInFrame(geometry)
                extent[j] = max(extent[j], np.linalg.norm(X_OG.translation()) + shape_radius(inspector.GetShape(geometry)))
    offsets = [np.linalg.norm(origins[j + 1].translation() - origins[j].translation()) for j in range(len(joints) - 1)]
    reach = np.zeros(len(joints))
    for j in range(len(joints)):
        along = 0.0
        for k in range(j, len(joints)):
            reach[j] = max(reach[j], along + extent[k])
            along += offsets[k] if k < len(offsets) else 0.0
    return reach


class ClearanceCheck:
    """The least SceneGraph distance along a plan and the intervals where the bound is not
    certified (module docstring). ``checker``: a cell check of the task's scene of its own (its
    plant and the pairs it checks); ``bound`` [m]: the distance to certify."""

    def __init__(self, robot, cell):
        self.probe = ClearanceProbe(robot, cell)
        self.reach = axis_reach(self.probe.checker, robot.joint_names)

    def distance(self, q) -> float:
        """SceneGraph's least signed distance [m] at ``q`` (a pair farther than 0.15 m reads as 0.15)."""
        return self.probe.distance(q, QUERY_WITHIN)

    def along(self, times, q, bound: float) -> dict:
        """``least``: the least distance at any sample taken [m] (and ``least_time`` [s]);
        ``below``: samples closer than ``bound``; ``uncertified``: 1 ms intervals between two
        samples at least ``bound`` apart where the bound is not certified in between;
        ``queries``: SceneGraph queries made. ``times`` (N,), ``q`` (N, n): the plan at the dense
        samples (every :data:`DENSE_PERIOD`)."""
        travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(q, axis=0)) @ self.reach)])
        stride = max(1, int(round(CLEARANCE_PERIOD / DENSE_PERIOD)))
        fine = np.append(np.arange(0, len(times) - 1, stride), len(times) - 1)
        distances = {}

        def at(index):
            if index not in distances:
                distances[index] = self.distance(q[index])
            return distances[index]

        stack = [(fine[a], fine[min(a + COARSE_STEPS, len(fine) - 1)]) for a in range(0, len(fine) - 1, COARSE_STEPS)]
        stack = stack or [(0, 0)]
        uncertified = 0
        position = {index: k for k, index in enumerate(fine)}
        while stack:
            a, b = stack.pop()
            if (at(a) + at(b)) / 2 - (travel[b] - travel[a]) >= bound:
                continue
            ka, kb = position[a], position[b]
            if kb - ka <= 1:
                uncertified += at(a) >= bound and at(b) >= bound and a != b
                continue
            middle = fine[(ka + kb) // 2]
            stack += [(a, middle), (middle, b)]
        least_index = min(distances, key=distances.get)
        return {"least": distances[least_index], "least_time": float(times[least_index]),
                "below": sum(value < bound for value in distances.values()), "uncertified": int(uncertified),
                "queries": len(distances)}


def rotation_angle(R_a, R_b) -> float:
    """The angle [rad] of the rotation between the 3x3 rotation matrices ``R_a`` and ``R_b``:
    atan2(|vee(E - Eᵀ)| / 2, (tr E - 1) / 2) with E = R_aᵀ R_b, exact to round-off at every angle
    (arccos of the trace alone cannot tell angles below about 1.5e-8 rad from 0)."""
    E = np.asarray(R_a).T @ np.asarray(R_b)
    sine = 0.5 * np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
    return float(np.arctan2(sine, (np.trace(E) - 1.0) / 2.0))


def pose_error(checker, robot, q, goal) -> tuple[float, float]:
    """(position error [m], orientation error [rad]) of the TCP at ``q`` against the task pose
    ``goal`` [x, y, z, φ_X, φ_Y, φ_Z] (Z-Y-X Euler angles: Drake's RollPitchYaw(φ_X, φ_Y, φ_Z)),
    by Drake's forward kinematics in the cell check ``checker``'s plant (the flange frame, then
    the robot's TCP offset)."""
    plant = checker.plant
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, checker.instance, np.asarray(q, dtype=float))
    X_WF = plant.GetFrameByName(robot.tool_frame, checker.instance).CalcPoseInWorld(context)
    X_WT = X_WF.GetAsMatrix4() @ robot.tcp_offset
    R_goal = RollPitchYaw(np.asarray(goal[3:6], dtype=float)).ToRotationMatrix().matrix()
    return float(np.linalg.norm(X_WT[:3, 3] - np.asarray(goal[:3]))), rotation_angle(R_goal, X_WT[:3, :3])


def tool_rates(checker, robot, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
    """(speed [m/s] (N,), acceleration magnitude [m/s²] (N,)) of the TCP at the samples ``q``,
    ``qd``, ``qdd`` (N, n), by Drake in the cell check ``checker``'s plant: v = J q̇ and
    a = J q̈ + J̇ q̇ (``CalcJacobianTranslationalVelocity``, ``CalcBiasTranslationalAcceleration``)
    of the TCP point in the flange frame, in the world (base) frame."""
    plant = checker.plant
    context = plant.CreateDefaultContext()
    flange, world = plant.GetFrameByName(robot.tool_frame, checker.instance), plant.world_frame()
    point = np.asarray(robot.tcp_offset)[:3, 3]
    speed, acceleration = np.zeros(len(q)), np.zeros(len(q))
    for k in range(len(q)):
        plant.SetPositions(context, checker.instance, q[k])
        plant.SetVelocities(context, checker.instance, qd[k])
        jacobian = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, flange, point, world, world)
        bias = plant.CalcBiasTranslationalAcceleration(context, JacobianWrtVariable.kV, flange, point, world, world)
        speed[k] = np.linalg.norm(jacobian @ qd[k])
        acceleration[k] = np.linalg.norm(jacobian @ qdd[k] + bias[:, 0])
    return speed, acceleration


def diagnose(error, robot, clearance: ClearanceCheck, cell_clearance: float) -> str:
    """Whether a refusal ``error`` (a DrakeTrajError) of a task on ``robot`` agrees with an
    independent diagnosis: "confirmed", "borderline: <why>", "supported: <why>", "contradicted:
    <why>" or "not diagnosed" (a cause, or a refusal without the configuration or pose, that the
    soak does not diagnose).
    A collision: SceneGraph (``clearance``'s query) puts the refused configuration closer than
    ``cell_clearance`` [m] (confirmed), within :data:`BORDERLINE` beyond it (borderline: the cell
    check refuses on the smaller of SceneGraph's distance and a certified lower bound, and
    SceneGraph's distance of cylinders and boxes can be millimetres above the true one), or further
    (contradicted). A joint range: the joint is past its range in the refused configuration. An
    unreachable pose: :func:`reach_diagnosis` (supported, borderline or contradicted)."""
    cause = str(getattr(error, "cause", ""))
    if cause == "collision" and getattr(error, "configuration", None) is not None:
        distance = clearance.distance(error.configuration)
        if distance < cell_clearance:
            return "confirmed"
        if distance < cell_clearance + BORDERLINE:
            return f"borderline: SceneGraph puts it {1e3 * (distance - cell_clearance):.3f} mm beyond the clearance"
        return f"contradicted: SceneGraph puts the refused configuration {1e3 * distance:.3f} mm from everything"
    if cause == "joint range" and getattr(error, "joint", None) is not None:
        j = error.joint
        q = np.asarray(error.configuration, dtype=float) if getattr(error, "configuration", None) is not None else None
        value = float(q[j]) if q is not None else float(error.value)
        if value < robot.lower_limits[j] or value > robot.upper_limits[j]:
            return "confirmed"
        return f"contradicted: joint {j + 1} at {value:.6f} is inside [{robot.lower_limits[j]:.6f}, {robot.upper_limits[j]:.6f}]"
    if cause == "unreachable":
        refused = in_chain(error, UnreachablePoseError)  # the arm's IK error, or what a planner made of it
        return "not diagnosed" if refused is None else reach_diagnosis(clearance.probe.checker, robot, refused.pose)
    return "not diagnosed"


def reach_diagnosis(checker, robot, pose, starts: int = IK_STARTS) -> str:
    """Whether the flange pose X_WF ``pose`` (4, 4) [m] (the arm's base is welded at the world
    origin, so an :class:`~drake_traj.errors.UnreachablePoseError`'s X_BF), refused as out of reach, is out of reach of
    Drake's InverseKinematics in the cell check ``checker``'s plant: the flange frame's position
    and orientation costs minimised within the plant's joint limits (SNOPT, or IPOPT, to an
    optimality tolerance of 1e-12) from ``starts`` seeded uniform starts within the robot's ranges,
    each result measured by forward kinematics. "contradicted: ..." where a solution within the
    ranges takes the pose to within :data:`IK_REACHED`; "borderline: ..." where the closest comes
    within :data:`IK_NEAR` only (a pose on the edge of the reach, where the solver converges
    slowly); "supported: ..." otherwise (evidence, not proof: a local solver)."""
    plant = checker.plant
    flange, world = plant.GetFrameByName(robot.tool_frame, checker.instance), plant.world_frame()
    pose = np.asarray(pose, dtype=float)
    target = RotationMatrix(pose[:3, :3])
    lower, upper = np.maximum(robot.lower_limits, -2 * np.pi), np.minimum(robot.upper_limits, 2 * np.pi)
    context = plant.CreateDefaultContext()
    full = plant.GetPositions(context)
    random = np.random.default_rng(0)
    closest = (np.inf, np.inf, None)  # (position error [m], orientation error [rad], q)
    for _ in range(starts):
        ik = InverseKinematics(plant, with_joint_limits=True)
        ik.AddPositionCost(world, pose[:3, 3], flange, np.zeros(3), np.eye(3))
        ik.AddOrientationCost(world, target, flange, RotationMatrix(), 1.0)
        plant.SetPositionsInArray(checker.instance, random.uniform(lower, upper), full)
        result = Solve(ik.prog(), full, _IK_OPTIONS)
        q = np.clip(plant.GetPositionsFromArray(checker.instance, result.GetSolution(ik.q())),
                    robot.lower_limits, robot.upper_limits)
        plant.SetPositions(context, checker.instance, q)
        X_WF = flange.CalcPoseInWorld(context).GetAsMatrix4()
        position = float(np.linalg.norm(X_WF[:3, 3] - pose[:3, 3]))
        turn = rotation_angle(pose[:3, :3], X_WF[:3, :3])
        if max(position, turn) < max(closest[:2]):
            closest = (position, turn, q)
        if max(position, turn) <= IK_REACHED:
            break
    position, turn, q = closest
    closest_text = f"{position * 1e3:.3g} mm and {turn:.3g} rad from the refused pose"
    if max(position, turn) <= IK_REACHED:
        return (f"contradicted: Drake's InverseKinematics takes the flange to {closest_text} at "
                f"q = {np.round(q, 6).tolist()}, within the joint ranges")
    if max(position, turn) <= IK_NEAR:
        return f"borderline: Drake's InverseKinematics takes the flange to {closest_text}, within the joint ranges"
    return (f"supported: Drake's InverseKinematics, from {starts} starts within the joint ranges, comes no closer "
            f"than {closest_text}")
