"""The benchmark on a tiny set: its table is consistent (not a timing test)."""

import csv

import numpy as np
import pytest

from drake_traj import bench


@pytest.fixture(scope="module")
def rows(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    table = bench.bench(out, count=1, repeats=1)
    with open(out / "bench.csv") as handle:
        assert len(list(csv.DictReader(handle))) == len(table)
    assert (out / "bench.md").read_text().startswith("## Paper task")
    assert (out / "bench.png").stat().st_size > 10_000
    return [row for row in table if row["task"] != "median"]


def test_every_planner_ran_on_every_task(rows):
    assert {(row["task"], row["planner"]) for row in rows} == {
        (task, name) for task in ("paper", "random_0") for name in bench.PLANNERS}
    assert all(row["succeeded"] for row in rows)


def test_no_planner_beats_the_time_optimal_bound_on_its_own_path(rows):
    # movej_blend breaks the acceleration limit in its blends, so it may beat the bound; Toppra's
    # grid is discrete: allow 2 % below the bound. NaN: Toppra found no parameterisation.
    assert all(np.isfinite(row["T_over_optimal"]) for row in rows if row["task"] == "paper")
    ratios = [row["T_over_optimal"] for row in rows if row["planner"] != "movej_blend"]
    assert np.nanmin(ratios) >= 0.98


def test_limits_where_promised_and_the_movej_blend_flaw(rows):
    for row in rows:
        if row["planner"] == "toppra":  # limits are kept on Toppra's grid; measured 2.2 % between
            assert row["max_qdd_over_limit"] <= 1.05, row
        elif row["planner"] != "movej_blend":
            assert row["max_qd_over_limit"] <= 1 + 1e-6, row
            assert row["max_qdd_over_limit"] <= 1 + 1e-6, row
    paper_movej = next(row for row in rows if row["task"] == "paper" and row["planner"] == "movej_blend")
    assert paper_movej["max_qdd_over_limit"] > 1.2  # blends superpose accelerations (paper: 2.48 vs 1.40)


def test_continuity_column(rows):
    by_name = {row["planner"]: row for row in rows if row["task"] == "paper"}
    assert by_name["pajak_blend"]["qdd_continuous"] and by_name["ruckig_stop"]["qdd_continuous"]
    assert not by_name["movej_blend"]["qdd_continuous"]  # trapezoids step in acceleration


def test_random_tasks_are_reachable_and_seeded():
    first, again = bench.random_tasks(3, seed=7), bench.random_tasks(3, seed=7)
    for (q0, poses), (_, poses_again) in zip(first, again):
        np.testing.assert_array_equal(poses, poses_again)
        joints = bench.joint_waypoints(q0, poses)
        for q, pose in zip(joints[1:], poses):
            np.testing.assert_allclose(bench.robot.task_pose(q)[:3], pose[:3], atol=1e-9)
