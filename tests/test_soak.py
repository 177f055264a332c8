"""The soak suite (drake_traj.bench.soak_*): its checks catch what they are for (each against a
computation of its own or a fault put in on purpose), its tasks are reproducible from their seeds,
and a CI-sized run of 100 tasks over every planner and arm has no wrong result."""

import csv

import numpy as np
import pytest
from pydrake.polynomial import Polynomial
from pydrake.trajectories import PiecewisePolynomial

import drake_traj.bench.soak_report as soak_report
import drake_traj.bench.soak_suite as soak_suite
from pydrake.math import RollPitchYaw, RotationMatrix
from drake_traj import cli
from drake_traj.bench import SOAK_ARMS, SOAK_PLANNERS, run_soak_task
from drake_traj.bench.soak_checks import (ClearanceCheck, dense_rates, diagnose, piece_coefficients, pose_error, rate_peaks,
                                          reach_diagnosis)
from drake_traj.bench.soak_suite import CLOSED_LOOP_EVERY, _check_plan
from drake_traj.bench.soak_tasks import draw_task
from drake_traj.cell import Box, Cell, CellChecker, CollisionError
from drake_traj.errors import Cause, DrakeTrajError, UnreachablePoseError, in_chain
from drake_traj.robots import UR10E

from conftest import interrupt_inside_compiled_code
from drake_traj.scenario.checks import preflight
from drake_traj.scenario.scenario import make_planner

# 10 tasks of every planner, spread over the arms; seed 50 (one in CLOSED_LOOP_EVERY) runs the closed loop too
CI_TASKS = [(SOAK_ARMS[(seed + k) % len(SOAK_ARMS)], planner, seed)
            for k, planner in enumerate(SOAK_PLANNERS) for seed in (*range(1, 10), 50)]


def _trajectory(pieces, breaks) -> PiecewisePolynomial:
    """A 1 x 1 PiecewisePolynomial of the coefficient lists ``pieces`` (ascending powers of the
    time since each piece's start)."""
    return PiecewisePolynomial([np.array([[Polynomial(c)]]) for c in pieces], breaks)


def test_exact_peaks_find_a_peak_inside_a_piece():
    # q = t^2/2 - t^3/3: q' = t (1 - t) peaks at 0.25 at t = 0.5, 0 at both ends; q'' = 1 - 2t peaks at 1
    # at the ends; q''' = -2. The second piece (from t = 1): q = 1/6 + 3 (t - 1)^2, q' = 6 (t - 1) up to 3.
    trajectory = _trajectory([[0.0, 0.0, 0.5, -1 / 3], [1 / 6, 0.0, 3.0]], [0.0, 1.0, 1.5])
    breaks, coefficients = piece_coefficients(trajectory)
    assert rate_peaks(breaks, coefficients, 1)[:, 0] == pytest.approx([0.25, 3.0], abs=1e-14)
    assert rate_peaks(breaks, coefficients, 2)[:, 0] == pytest.approx([1.0, 6.0], abs=1e-14)
    assert rate_peaks(breaks, coefficients, 3)[:, 0] == pytest.approx([2.0, 0.0], abs=1e-14)
    # a 0.1 ms grid that misses t = 0.5 by 0.05 ms still finds the peak within 1e-8
    times, rates = dense_rates(trajectory, period=1.5e-4)
    assert 0.25 - np.max(np.abs(rates[1][times < 1.0])) < 1e-8


def test_exact_peaks_match_dense_sampling_on_a_real_plan():
    task = draw_task("ur10e", "smooth_waypoints", 5)
    planner = make_planner(task.scenario)
    plan = planner.plan()
    breaks, coefficients = piece_coefficients(plan)
    times, rates = dense_rates(plan, period=2e-5)
    for order in (1, 2, 3):
        exact = rate_peaks(breaks, coefficients, order).max(axis=0)
        sampled = np.abs(rates[order]).max(axis=0)
        assert np.all(exact >= sampled - 1e-9) and np.allclose(exact, sampled, rtol=1e-3)


def test_pose_error_is_drakes_forward_kinematics():
    checker = CellChecker(UR10E)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-2, 2, 6)
        assert pose_error(checker, UR10E, q, UR10E.tcp_pose(q)) == pytest.approx((0.0, 0.0), abs=2e-7)
        moved = UR10E.tcp_pose(q) + np.array([0.003, -0.004, 0.0, 0.0, 0.0, 0.0])
        assert pose_error(checker, UR10E, q, moved)[0] == pytest.approx(0.005, abs=1e-9)


@pytest.fixture(scope="module")
def planned_quintic():
    """The first quintic task on the UR10e that the preflight accepts, planned."""
    for seed in range(1, 40):
        task = draw_task("ur10e", "quintic", seed)
        planner = make_planner(task.scenario)
        try:
            preflight(task.scenario, planner)
        except ValueError:
            continue
        return task, planner
    raise AssertionError("no quintic task of seeds 1-39 was planned")


def test_a_good_plan_passes_every_check(planned_quintic):
    task, planner = planned_quintic
    values, wrongs = _check_plan(task, planner)
    assert wrongs == []
    # Benotsmane et al.'s synchronised quintic: the slowest joint reaches its velocity or acceleration limit
    assert max(values["velocity_fraction"], values["acceleration_fraction"]) == pytest.approx(1.0, abs=1e-9)
    assert values["least_distance_m"] >= task.scenario.cell.clearance


def test_the_checks_catch_a_limit_and_a_goal_put_wrong(planned_quintic):
    task, planner = planned_quintic
    promised = planner.velocity_limit.copy()
    values, _ = _check_plan(task, planner)
    try:
        planner.velocity_limit = promised * 0.5  # the plan now exceeds what the planner says it keeps
        _, wrongs = _check_plan(task, planner)
    finally:
        planner.velocity_limit = promised
    assert f"velocity {2 * values['velocity_fraction']:.9f} of its limit" in wrongs
    goals = task.scenario.planner.goals
    try:
        task.scenario.planner.goals = [*goals[:-1], (np.asarray(goals[-1]) + 1e-4).tolist()]
        _, wrongs = _check_plan(task, planner)
    finally:
        task.scenario.planner.goals = goals
    assert any("from its last goal" in wrong for wrong in wrongs)


def test_the_clearance_check_finds_a_dip_between_its_samples():
    # joint 1 turns 1.2 rad in 2 s and the flange passes a 2 mm cube at mid-motion: the check must
    # refine down to it (its first samples are 64 ms apart) and find SceneGraph's least distance there
    start = np.array([0.0, -1.2, 1.2, -1.57, -1.57, 0.0])
    turn = np.array([1.2, 0.0, 0.0, 0.0, 0.0, 0.0])
    flange = UR10E.tcp_pose(start + turn / 2)[:3]
    cell = Cell(obstacles=[Box(name="cube", size=[0.002, 0.002, 0.002], xyz=flange.tolist())])
    check = ClearanceCheck(UR10E, cell)
    times = np.linspace(0.0, 2.0, 20001)  # the 0.1 ms samples
    q = start + np.outer(times / 2.0, turn)
    along = check.along(times, q, cell.clearance / 2)
    brute = min(check.distance(row) for row in q[::10])  # every 1 ms
    assert brute < 0 and along["below"] > 0 and along["least"] == pytest.approx(brute, abs=1e-9)
    assert along["queries"] < 1000  # refined where it dips, not sampled every millisecond
    clear = ClearanceCheck(UR10E, Cell()).along(times, q, 0.005)
    assert clear["below"] == 0 and clear["queries"] < 200  # of the 2001 millisecond samples


def test_a_refusal_is_diagnosed_independently():
    robot = UR10E
    cell = Cell()
    check = ClearanceCheck(robot, cell)
    into_table = np.array([0.0, -0.3, 2.0, -1.57, -1.57, 0.0])
    clear = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])
    assert check.distance(into_table) < 0 < 0.1 < check.distance(clear) + 0.1
    made = dict(bodies=("wrist_2_link", "table"), distance=-0.01, clearance=0.01)
    assert diagnose(CollisionError("refused", configuration=into_table, time=0.0, **made), robot, check,
                    0.01) == "confirmed"
    assert diagnose(CollisionError("refused", configuration=clear, time=0.0, **made), robot, check,
                    0.01).startswith("contradicted")
    # refused within 1 mm beyond the clearance by SceneGraph: the check's certified bound may be below it
    beyond = check.distance(clear) - 0.0005
    assert diagnose(CollisionError("refused", configuration=clear, time=0.0, **made), robot, check,
                    beyond).startswith("borderline: SceneGraph puts it 0.500 mm beyond")


def _flange_pose(check, robot, q) -> np.ndarray:
    """X_WF (4, 4) of ``robot``'s flange at ``q`` by Drake, in ``check``'s plant."""
    plant, checker = check.probe.checker.plant, check.probe.checker
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, checker.instance, q)
    return plant.GetFrameByName(robot.tool_frame, checker.instance).CalcPoseInWorld(context).GetAsMatrix4()


@pytest.mark.parametrize("arm", ["ur10e", "puma560"])
def test_an_unreachable_pose_is_diagnosed_by_drakes_inverse_kinematics(arm):
    task = draw_task(arm, "li", 3)
    robot = task.scenario.robot_with_tool()
    check = ClearanceCheck(robot, task.scenario.cell)
    q = np.clip([0.4, -1.2, 1.3, -1.0, 1.1, 0.3], robot.lower_limits + 0.1, robot.upper_limits - 0.1)
    reached = _flange_pose(check, robot, q)
    far = reached.copy()
    far[:3, 3] *= 4  # several metres out: beyond either arm's reach
    with pytest.raises(UnreachablePoseError) as refused:  # the arm's own IK (UR: the flange's pose, PUMA: the TCP's)
        robot.inverse_kinematics_all(far if arm == "ur10e" else _task_pose(far @ robot.tcp_offset))
    assert refused.value.cause is Cause.UNREACHABLE
    np.testing.assert_allclose(refused.value.pose, far, atol=1e-9)  # the flange pose, in the plant's world
    moved = refused.value.relocated(("planner", "points", 3), "moved")  # as a planner passes it on
    assert diagnose(moved, robot, check, 0.01).startswith("supported: Drake's InverseKinematics, from 32 starts")
    # a pose the arm takes at q, refused by a made-up error: contradicted, with a solution that takes it
    wrong = UnreachablePoseError("made up", pose=reached)
    verdict = diagnose(wrong, robot, check, 0.01)
    assert verdict.startswith("contradicted: Drake's InverseKinematics takes the flange to")
    solution = np.array(verdict.split("q = ")[1].split("]")[0].strip("[").split(","), dtype=float)
    np.testing.assert_allclose(_flange_pose(check, robot, solution), reached, atol=1e-6)
    if arm == "ur10e":  # just beyond the edge of the reach (the arm straight up, 3 µm higher): borderline
        edge = _flange_pose(check, robot, np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0]))
        edge[2, 3] += 3e-6
        verdict = reach_diagnosis(check.probe.checker, robot, edge)
        assert verdict.startswith("borderline: Drake's InverseKinematics takes the flange to ")
        assert float(verdict.split(" to ")[1].split(" mm")[0]) == pytest.approx(0.003, abs=2e-5)
    # an unreachable refusal without its pose (a branch's reach) is not diagnosed
    assert diagnose(DrakeTrajError("branch", cause=Cause.UNREACHABLE), robot, check, 0.01) == "not diagnosed"


def test_a_task_refused_as_unreachable_gets_drakes_diagnosis():
    # soak ur3e / li / 3: the wrist centre of points[18] is 0.126 m from the joint-1 axis, inside
    # the shoulder offset d4 = 0.131 m; Drake's IK gets no nearer than 5.46 mm
    row = run_soak_task("ur3e", "li", 3)
    assert row["outcome"] == "refused" and row["cause"] == "unreachable" and not row["wrong"]
    assert row["diagnosis"].startswith("supported: Drake's InverseKinematics, from 32 starts within the joint ranges, "
                                       "comes no closer than 5.46 mm")


def test_the_unreachable_pose_is_found_behind_what_a_planner_made_of_it():
    far = np.eye(4)
    far[:3, 3] = [4.0, 0.0, 1.0]
    try:
        try:
            UR10E.inverse_kinematics_all(far)
        except DrakeTrajError as error:  # a planner's own refusal, then relocated as a scenario does
            raise DrakeTrajError(f"pose 0 cannot be reached: {error}", field=("poses", 0),
                                 cause=Cause.UNREACHABLE) from error
    except DrakeTrajError as refusal:
        try:
            raise refusal.relocated(("planner", "poses", 0), f"planner.poses[0]: {refusal}") from None
        except DrakeTrajError as relocated:
            found = in_chain(relocated, UnreachablePoseError)
    assert isinstance(found, UnreachablePoseError) and np.array_equal(found.pose, far)
    assert in_chain(DrakeTrajError("no pose behind it", cause=Cause.UNREACHABLE), UnreachablePoseError) is None


def _task_pose(X) -> np.ndarray:
    """[x, y, z, φ_X, φ_Y, φ_Z] of the 4x4 pose ``X`` (Z-Y-X Euler angles, Drake's RollPitchYaw)."""
    return np.concatenate([X[:3, 3], RollPitchYaw(RotationMatrix(X[:3, :3])).vector()])


def test_a_stop_inside_a_task_stops_the_soak(monkeypatch):
    """Ctrl-C or SIGTERM while a task runs compiled code (Pająk's integration) surfaces as a
    SystemError: the task raises the interrupt (which stops the soak), never a row of a task's error."""
    monkeypatch.setattr(soak_suite, "preflight", interrupt_inside_compiled_code)
    with pytest.raises(KeyboardInterrupt):
        run_soak_task("ur10e", "quintic", 3)
    monkeypatch.setattr(soak_suite, "preflight", lambda scenario, planner: 1 / 0)  # a bug of its own: a wrong row
    row = run_soak_task("ur10e", "quintic", 3)
    assert row["outcome"] == "error" and row["wrong"] and row["message"].startswith("ZeroDivisionError")


def test_tasks_are_drawn_from_their_seed_alone():
    first, again = draw_task("ur5e", "pajak", 7), draw_task("ur5e", "pajak", 7)
    assert first.params == again.params and first.scenario.q_initial == again.scenario.q_initial
    assert first.scenario.planner.waypoints == again.scenario.planner.waypoints
    assert draw_task("ur5e", "pajak", 8).params != first.params
    assert draw_task("ur5e", "pajak_retimed", 7).params != first.params  # each planner its own draws


def test_a_hundred_tasks_of_every_planner_and_arm_have_no_wrong_result():
    rows = [run_soak_task(*task) for task in CI_TASKS]
    wrong = [f"{row['arm']} {row['planner']} {row['seed']}: {row['message']}" for row in rows if row["wrong"]]
    assert wrong == []
    outcomes = {row["outcome"] for row in rows}
    assert outcomes <= {"planned", "refused"} and sum(row["outcome"] == "planned" for row in rows) >= 40
    loops = [row for row in rows if row["seed"] % CLOSED_LOOP_EVERY == 0 and row["outcome"] == "planned"]
    assert loops and all(row["closed_loop"] == "succeeded" for row in loops)


def test_the_command_writes_its_report_and_reruns_a_task(tmp_path):
    out = tmp_path / "soak"
    code = cli.main(["bench", "--suite", "soak", "--arms", "ur10e", "--planners", "quintic", "ruckig", "--count", "2",
                     "--seed", "49", "--workers", "1", "--out", str(out), "--quiet"])
    assert code == 0
    with open(out / "soak.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert [(row["planner"], row["seed"]) for row in rows] == [("quintic", "49"), ("quintic", "50"), ("ruckig", "49"),
                                                               ("ruckig", "50")]
    assert all(row["rerun"].startswith("drake-traj bench --suite soak --arms ur10e") for row in rows)
    assert "| ur10e | quintic | 2 |" in (out / "soak.md").read_text() and (out / "soak.png").stat().st_size > 10_000
    again = run_soak_task("ur10e", "quintic", 49)
    first = rows[0]
    assert again["outcome"] == first["outcome"] and again["params"] == first["params"]
    # a second part (seed 51) merged with the first into one report; a task in two parts is refused
    part = tmp_path / "part"
    assert cli.main(["bench", "--suite", "soak", "--arms", "ur10e", "--planners", "quintic", "--count", "1",
                     "--seed", "51", "--workers", "1", "--out", str(part), "--quiet"]) == 0
    merged = tmp_path / "merged"
    assert cli.main(["bench", "--suite", "soak", "--merge", str(out), str(part), "--out", str(merged), "--quiet"]) == 0
    text = (merged / "soak.md").read_text()
    assert "5 tasks, seeds 49-51, merged from parts" in text and "| ur10e | quintic | 3 |" in text
    assert cli.main(["bench", "--suite", "soak", "--merge", str(out), str(out), "--out", str(tmp_path / "twice")]) == 2


def test_a_local_soak_makes_its_cluster_afresh_every_chunk(tmp_path, monkeypatch):
    import drake_traj.bench.soak_report as report

    made = []
    engine = report._engine

    def counted(workers, scheduler):
        made.append(workers)
        return engine(workers, scheduler)

    monkeypatch.setattr(report, "LOCAL_CHUNK", 2)
    monkeypatch.setattr(report, "_engine", counted)
    rows = report.soak_bench(tmp_path / "soak", count=3, arms=("ur10e",), planners=("quintic",), workers=2,
                             progress=None)
    assert made == [2, 2] and [row["seed"] for row in rows] == [0, 1, 2]
    assert [row["params"] for row in rows] == [run_soak_task("ur10e", "quintic", seed)["params"] for seed in range(3)]


def test_an_interrupted_soak_writes_the_tasks_it_finished(tmp_path, monkeypatch):
    """Ctrl-C (a KeyboardInterrupt; SIGTERM arrives as one) on the third task: the two tasks done
    are written as a part (soak.md says how far it got) and the interrupt goes on, noted."""
    def interrupted_on_the_third(arm, planner, seed):
        if seed == 2:
            raise KeyboardInterrupt
        return run_soak_task(arm, planner, seed)

    monkeypatch.setattr(soak_report, "run_soak_task", interrupted_on_the_third)
    with pytest.raises(KeyboardInterrupt) as stop:
        soak_report.soak_bench(tmp_path / "soak", count=4, arms=("ur10e",), planners=("quintic",), workers=1,
                               progress=None)
    assert any("stopped after 2 of 4 tasks" in note for note in stop.value.__notes__)
    with open(tmp_path / "soak" / "soak.csv") as handle:
        assert [row["seed"] for row in csv.DictReader(handle)] == ["0", "1"]
    assert "2 tasks, seeds 0-1" in (tmp_path / "soak" / "soak.md").read_text()
    assert "stopped after 2 of 4 tasks" in (tmp_path / "soak" / "soak.md").read_text()
    with pytest.raises(KeyboardInterrupt) as stop:  # before any task ended: nothing to write
        soak_report.soak_bench(tmp_path / "none", count=4, seed=2, arms=("ur10e",), planners=("quintic",), workers=1,
                               progress=None)
    assert any("stopped after 0 of 4 tasks, nothing written" in note for note in stop.value.__notes__)
    assert not (tmp_path / "none" / "soak.csv").exists()


def test_bad_arguments_are_refused_before_any_task(tmp_path, capsys):
    assert cli.main(["bench", "--suite", "soak", "--arms", "ur11e", "--out", str(tmp_path / "a")]) == 2
    assert "arms (--arms) must be some of" in capsys.readouterr().err
    assert cli.main(["bench", "--suite", "soak", "--count", "0", "--out", str(tmp_path / "b")]) == 2
    assert not (tmp_path / "a").exists()
