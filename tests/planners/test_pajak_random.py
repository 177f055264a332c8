"""The Pająk 2024 planner on tasks that are not the paper's: 200 seeded random tasks,
each event that used to make q̈ jump, and the preflight.

The tasks are made like the issue's: walks in joint space from the paper's q(0), each of 1-4
waypoints a step of up to 0.7 rad per joint from the previous one (the waypoint is its flange
pose), and random limits 0.5-2 rad/s and 0.7-3 rad/s² (one value for every joint or one per
joint, by a fair coin). The law runs alone under its own RK4 integrator at 1 ms; no timing here.
"""

import dataclasses

import numpy as np
import pytest

from drake_traj.bench import pajak_walk_tasks
from drake_traj.planners import pajak as P
from drake_traj.planners.pajak.kernel import Discrete
from drake_traj.robots import task_space
from drake_traj.robots import ur10e as robot

Q0 = P.paper_initial_configuration()
STEP = 0.1  # [rad/s²]: the largest change of q̈ between 1 ms samples that counts as continuous
TOL = 1e-9  # floating-point slack on "limit held"


def random_tasks(count: int = 200, seed: int = 9) -> list[P.PajakConfig]:
    """``count`` valid tasks of moves of up to 0.7 rad per joint, seeded (bench.pajak_walk_tasks).
    The law is integrated alone here, without the arm's body or a cell: the set is not filtered
    for collisions, so that the measured set (README "Beyond the paper's task") stays the same."""
    return pajak_walk_tasks(count, seed, step=0.7)


def largest_step(qdd: np.ndarray) -> float:
    """The largest change of q̈ between consecutive samples after t = 0 [rad/s²]."""
    return float(np.abs(np.diff(qdd[1:], axis=0)).max())


def run(task: P.PajakConfig, **kwargs) -> tuple[dict, P.PlanningError | None]:
    """(the integrated log, the PlanningError it ended with or None)."""
    try:
        return P.integrate(P.PajakLaw(task), Q0, **kwargs), None
    except P.PlanningError as error:
        return error.partial, error


@pytest.fixture(scope="module")
def random_runs():
    tasks = random_tasks()
    return tasks, [run(task, settle_time=0.5) for task in tasks]


def test_random_tasks(random_runs):
    tasks, runs = random_runs
    continuous, finished, causes = 0, 0, {}
    for task, (result, error) in zip(tasks, runs):
        law = P.PajakLaw(task)
        # no NaN; the limits hold at every sample and at every RK4 stage (the settling included)
        assert np.all(np.isfinite(result["qdd"])) and np.all(np.isfinite(result["q"]))
        assert np.all(result["stage_peak"] <= law.qdd_max + TOL)
        assert np.all(result["stage_velocity_peak"] <= law.qd_max)
        assert np.all((result["c"] >= 0.0) & (result["c"] <= 1.0))
        if error is None:
            finished += 1
            # the whole pose at the finish (position within ε, orientation within 1 mrad)
            assert result["error"] < task.accuracy and result["orientation_error"] < task.orientation_accuracy
            end = result["finish_index"] + 1 + 500  # through the finish and 0.5 s past it
        else:
            # every failure is a PlanningError with its cause, time and configuration
            assert error.cause in ("stall", "singular") and error.time > 0 and error.configuration.shape == (6,)
            causes[error.cause] = causes.get(error.cause, 0) + 1
            end = len(result["t"])
        continuous += largest_step(result["qdd"][:end]) <= STEP
    print(f"\n200 random tasks: {finished} finished, failures {causes}, q̈ continuous on {continuous}")
    # Measured: 192 finished (8 stalls, 6 of them near a singular configuration), q̈ continuous
    # on all 200 (median largest change 0.037 rad/s², the largest 0.080: the jerk limit of 80 rad/s³).
    # Before the jerk limit: 199 of 200 (191 of the 192 finished). Before the
    # jerk-limited viability bound and the penalty's stiffness cap of 150 1/s (was 300): 196
    # (188 of 192), the largest change 0.125 rad/s²; now 0.107. Before the 300 1/s cap and the
    # continuous orientation error: continuous on 195 (187 of 192), the largest change
    # 0.63 rad/s². Before the jerk budget: 191 finished, continuous on 187 (181 of 191). The one
    # left changed q̈ by 0.107 rad/s² in 1 ms and by half that at 0.5 ms (steep, not a jump:
    # examples/pajak_sweep.py).
    assert finished >= 190
    assert continuous == 200


def test_the_jerk_limit_holds_on_every_task(random_runs):
    # improvement 1's jerk limit (jerk_limit, 80 rad/s³): q̈ changes by at most 0.08 rad/s² between
    # 1 ms samples on every task, through the finish and 0.5 s past it or up to a failure. Without
    # it, task 156 changed q̈ by 0.107 rad/s² within 1 ms and by about half that at 0.5 ms (steep,
    # not a jump); the limit leaves its finish time as it was
    tasks, runs = random_runs
    steps = [largest_step(result["qdd"][: end_of_run(result, error)]) for result, error in runs]
    assert max(steps) <= 0.08 + 1e-9
    free = dataclasses.replace(tasks[156], jerk_limit=1e9)
    coarse, _ = run(free, settle_time=0.5)
    fine, _ = run(free, dt=5e-4, t_max=coarse["T"] + 0.5, raise_on_timeout=False)
    assert largest_step(coarse["qdd"]) == pytest.approx(0.107, abs=5e-4)
    assert largest_step(fine["qdd"]) < 0.7 * largest_step(coarse["qdd"])
    assert runs[156][0]["T"] == coarse["T"]


def end_of_run(result: dict, error) -> int:
    """Samples that count for continuity: through the finish and 0.5 s past it, or all of a failed run."""
    return len(result["t"]) if error is not None else result["finish_index"] + 1 + 500


@pytest.mark.parametrize("index, cause", [(29, "blend"), (119, "scaling"), (138, "approach")])
def test_jerk_budget_keeps_qdd_continuous(random_runs, index, cause):
    # improvement 1's jerk budget (40 rad/s³): c, the blend's σ and the approach rate of
    # improvement 4 change q̈ no faster than that, one task of the seeded set for each. Without
    # it these tasks changed q̈ by 0.17 (a blend entered at speed on a long leg: σ moved the
    # target at 8x the TCP's speed), 0.20 (c of a few 10⁻³ rising by eq. 18 with |b| near
    # 200 rad/s², the penalty active) and 0.15 rad/s² (the TCP sweeping past p_w within
    # millimetres: the approach rate, and with it the damping, collapsed within 5 ms) in 1 ms.
    tasks, runs = random_runs
    task, (result, error) = tasks[index], runs[index]
    law = P.PajakLaw(task)
    assert largest_step(result["qdd"][: end_of_run(result, error)]) <= STEP
    assert np.all(result["stage_peak"] <= law.qdd_max + TOL)
    assert np.all(result["stage_velocity_peak"] <= law.qd_max)
    d = result["discrete"]
    if cause == "blend":  # σ behind the TCP's path through the ball
        path = d[:, Discrete.TRAVEL] / (task.blend_length * task.neighbourhood)
        blending = d[:, Discrete.BLENDING] > 0.5
        assert np.any(blending & (d[:, Discrete.SIGMA] < np.minimum(path, 1.0) - 0.05))
        assert error is None
    elif cause == "scaling":  # c rose by less than half of what eq. 18 asked for
        assert error is not None and error.cause == "stall"  # near a singular configuration, later
        asked = np.array([law.evaluate(result["t"][k], result["q"][k], result["qd"][k], d[k - 1])["c_relaxed"]
                          for k in range(1, len(d))]) - result["c"][:-1]
        rose = np.diff(result["c"])
        assert np.any((asked > 1e-4) & (rose > 0) & (rose < 0.5 * asked))
    else:  # the approach rate held above the TCP's rate of closing on p_w
        goal = task.waypoints[-1]
        closing = []
        for q, qd in zip(result["q"], result["qd"]):
            error_now = task_space.task_pose_error(robot.task_pose(q), goal)
            closing.append(P.approach_rate(error_now, robot.analytic_jacobian(q) @ qd, 1e-4 * task.accuracy))
        final = result["waypoint"] == len(task.waypoints) - 1
        assert np.any(final & (d[:, Discrete.APPROACH] > np.array(closing) + 1.0))
        assert error is None
    # a budget no rate reaches: the same task as before the budget. Task 119 no longer needs it:
    # with the penalty's stiffness capped (kernel.PENALTY_STIFFNESS) |b| stays far lower there,
    # and without the budget q̈ changes by 0.043 rad/s² in 1 ms at most (measured)
    # (and no jerk limit, which would hide them)
    unbudgeted, failure = run(dataclasses.replace(task, jerk_budget=1e9, jerk_limit=1e9), settle_time=0.5)
    unbudgeted_step = largest_step(unbudgeted["qdd"][: end_of_run(unbudgeted, failure)])
    assert unbudgeted_step > 1.4 * STEP if cause != "scaling" else unbudgeted_step < 0.5 * STEP


def test_literal_scaling_diverges_where_bounded_scaling_holds(random_runs):
    # improvement 2: the paper's choice of c leaves [0, 1] (which switches the penalty off or
    # reverses the feedback) on some of these tasks; ours keeps c in [0, 1] and the limits there
    tasks, runs = random_runs
    diverged = 0
    for task, (result, _) in zip(tasks[:20], runs[:20]):
        literal, _ = run(dataclasses.replace(task, bounded_scaling=False), t_max=5.0, raise_on_timeout=False)
        if not np.all(np.isfinite(literal["qdd"])) or literal["c"].min() < 0 or literal["c"].max() > 1:
            diverged += 1
            assert np.all((result["c"] >= 0) & (result["c"] <= 1))
            assert np.all(result["stage_peak"] <= P.PajakLaw(task).qdd_max + TOL)
    assert diverged >= 2


def update_part(law: P.PajakLaw, result: dict, k: int) -> float:
    """How much the discrete update at sample k alone changes q̈ (same time and state)."""
    before = law.evaluate(result["t"][k], result["q"][k], result["qd"][k], result["discrete"][k - 1])["qdd"]
    after = law.evaluate(result["t"][k], result["q"][k], result["qd"][k], result["discrete"][k])["qdd"]
    return float(np.abs(after - before).max())


def test_anchor_of_eq_18_does_not_move_qdd():
    # the updates that record the eq. 18 anchor while the limits set c (improvement 4's damping
    # used to be sized by 1/c_r there, and c_r drops to c at each such update)
    law = P.PajakLaw(P.paper_parameters(3))
    result = P.integrate(law, Q0)
    d = result["discrete"]
    anchors = np.flatnonzero(d[1:, Discrete.T0] == result["t"][1:]) + 1
    assert anchors.size > 1000
    assert max(update_part(law, result, k) for k in anchors) < 1e-12


def test_waypoint_switches_do_not_move_qdd():
    # entering a ball (σ from 0) and switching to the next waypoint (σ = 1) on four-waypoint tasks
    for task in [t for t in random_tasks(40) if len(t.waypoints) == 4][:3]:
        law = P.PajakLaw(task)
        result, _ = run(task)
        d = result["discrete"]
        events = np.flatnonzero((np.diff(d[:, Discrete.WAYPOINT]) != 0) | (np.diff(d[:, Discrete.BLENDING]) != 0)) + 1
        assert events.size >= 4
        assert max(update_part(law, result, k) for k in events) < 1e-12


def test_braking_fallback_is_continuous():
    # task 36 of the seeded set: a = -J⁻¹J̇q̇ alone leaves the box, no c in [0, 1] keeps the
    # limits, and the fallback brakes fully (weight 1) before handing back to the law
    task = random_tasks(37)[36]
    law = P.PajakLaw(task)
    result = P.integrate(law, Q0)
    evaluations = [law.evaluate(t, q, qd, d) for t, q, qd, d in
                   zip(result["t"], result["q"], result["qd"], result["discrete"])]
    violation = np.array([e["violation"] for e in evaluations])
    brake = np.array([e["brake"] for e in evaluations])
    assert violation.max() > 0.5 and brake.max() > 0.99 and brake[-1] == 0.0
    assert largest_step(result["qdd"]) <= STEP
    assert result["discrete"][-1, Discrete.SATURATED] > 0  # counted
    assert np.all(result["stage_peak"] <= law.qdd_max + TOL)


def test_finish_does_not_move_qdd():
    # the law goes on after the finish (the station keeps the planner running while the arm
    # settles): nothing changes there, and the TCP stays at the pose
    task = random_tasks(1)[0]
    result = P.integrate(P.PajakLaw(task), Q0, settle_time=1.0)
    k = result["finish_index"]
    assert largest_step(result["qdd"][k - 200:]) <= STEP
    position, orientation = robot.pose_error(result["tcp"][k:], task.waypoints[-1])
    assert position.max() < task.accuracy and orientation.max() < task.orientation_accuracy


def test_orientation_is_part_of_the_finish():
    # legs that turn the tool by about 0.4 rad each: the position is within ε before the
    # orientation is within 1 mrad; the task finishes only when both are
    q1 = Q0 + np.array([0.3, -0.2, 0.3, 0.4, -0.4, 0.4])
    q2 = q1 + np.array([0.2, 0.2, -0.2, -0.4, 0.4, -0.4])
    task = P.PajakConfig(waypoints=[robot.task_pose(q1), robot.task_pose(q2)])
    result = P.integrate(P.PajakLaw(task), Q0)
    position, orientation = robot.pose_error(result["tcp"], task.waypoints[-1])
    final = result["waypoint"] == 1
    first_in_position = np.argmax(final & (position < task.accuracy))
    assert orientation[first_in_position] > task.orientation_accuracy
    assert result["error"] < task.accuracy and result["orientation_error"] < task.orientation_accuracy
    assert result["T"] > result["t"][first_in_position]


def test_preflight_raises_for_an_unreachable_waypoint_before_moving():
    pose = robot.task_pose(Q0)
    unreachable = pose.copy()
    shoulder = np.array([0.0, 0.0, robot.DH_D[0]])
    direction = (pose[:3] - shoulder) / np.linalg.norm(pose[:3] - shoulder)
    unreachable[:3] = shoulder + 1.29 * direction  # inside the 1.3 m reach, but not with this orientation
    planner = P.PajakPlanner(P.PajakConfig(waypoints=[pose + [0.1, 0, 0, 0, 0, 0], unreachable]), Q0)
    with pytest.raises(P.PlanningError) as info:
        planner.preflight()
    error = info.value
    assert error.cause == "unreachable" and error.time == 0.0
    assert "waypoint 1 cannot be reached" in str(error) and "out of reach" in str(error)


def test_preflight_raises_for_a_stalling_task_before_moving():
    # the goal is the pose of a configuration 0.02 rad from the wrist singularity (q5 = 0): the
    # damped inverse stops 9 mm short of it
    q_goal = Q0 + np.array([0.3, 0.2, 0.0, 0.0, 0.0, 0.0])
    q_goal[4] = 0.02
    planner = P.PajakPlanner(P.PajakConfig(waypoints=robot.task_pose(q_goal)[None]), Q0)
    with pytest.raises(P.PlanningError) as info:
        planner.preflight()
    error = info.value
    assert error.cause == "stall" and 3.0 < error.time < 10.0
    assert "no progress towards waypoint 0" in str(error) and "near a singular configuration" in str(error)


def test_preflight_returns_the_tool_path():
    planner = P.PajakPlanner(P.paper_parameters(3), Q0)
    path = planner.preflight()
    assert path.shape[1] == 3 and len(path) == 5333  # 5.332 s at 1 ms, t = 0 included
    np.testing.assert_allclose(path[0], robot.task_pose(Q0)[:3], atol=1e-12)
    assert np.linalg.norm(path[-1] - planner.goal_pose()[:3]) < 1e-3
