"""The free-motion scenes and their suite (``drake-traj bench --suite free``): every generator is
reproducible from its seed, every query is feasible (its witness path keeps 12 mm by a dense
SceneGraph check of the test's own, not the generator's), starts and goals lie inside the joint
ranges and clear of the cell, and a tiny suite writes its table (not a timing test)."""

import csv

import numpy as np
import pytest

from drake_traj import cli
from drake_traj.bench.free_scenes import SCENE_KINDS, WITNESS_CLEARANCE, dense_path, forearm_radius, generate
from drake_traj.bench.free_suite import FREE_COLUMNS, FREE_FILES, ClearanceProbe, free_bench
from drake_traj.robots import get_robot

SEED = 3


@pytest.fixture(scope="module")
def scenes():
    return {kind: generate(kind, SEED) for kind in SCENE_KINDS}


def obstacles(scene) -> list:
    return [(box.name, box.size, box.xyz, box.rpy) for box in scene.cell.obstacles]


@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_a_scene_is_reproducible_from_its_seed(kind, scenes):
    again, other = generate(kind, SEED), generate(kind, SEED + 1)
    scene = scenes[kind]
    assert obstacles(again) == obstacles(scene) and again.cell.tool == scene.cell.tool
    for mine, theirs in zip(scene.queries, again.queries, strict=True):
        for name in ("start", "goal", "witness", "pose"):
            np.testing.assert_array_equal(getattr(mine, name), getattr(theirs, name))
    assert not np.array_equal(other.queries[0].start, scene.queries[0].start)


@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_every_witness_keeps_12_mm_by_an_independent_check(kind, scenes):
    scene = scenes[kind]
    probe = ClearanceProbe(scene.robot, scene.cell)
    for query in scene.queries:
        np.testing.assert_array_equal(query.witness[0], query.start)
        np.testing.assert_array_equal(query.witness[-1], query.goal)
        # samples at most 1 mm of any point's travel apart (2 m per rad of any joint bounds it, the
        # UR10e's and the tool's reach 1.81 m at most: not the check's bounds)
        nearest = probe.along(dense_path(query.witness, np.full(len(query.start), 2.0), 1e-3), within=0.02)
        assert nearest >= WITNESS_CLEARANCE, (kind, nearest)


@pytest.mark.parametrize("kind", SCENE_KINDS)
def test_starts_and_goals_lie_in_the_ranges_and_clear_of_the_cell(kind, scenes):
    scene = scenes[kind]
    probe = ClearanceProbe(scene.robot, scene.cell)
    low, high = scene.robot.lower_limits, scene.robot.upper_limits
    for query in scene.queries:
        for q in (query.start, query.goal):
            assert np.all((low <= q) & (q <= high))
            assert probe.distance(q) >= scene.cell.clearance
        if query.pose is not None:  # a pose goal: the TCP pose of the witness's end, the tool's TCP
            np.testing.assert_allclose(scene.robot.tcp_pose(query.goal), query.pose, atol=1e-12)
            assert query.config().poses == [query.pose.tolist()]
        else:
            assert query.config(planning_time=2.0).goals == [query.goal.tolist()]


def test_what_each_kind_is_made_of(scenes):
    assert not scenes["open"].cell.obstacles
    assert 10 <= len(scenes["clutter"].cell.obstacles) <= 15
    for kind in ("shelf", "pose_in_cubby"):  # the 0.12 m tool, the planner's TCP at its tip
        assert scenes[kind].cell.tool.tcp_xyz == [0.0, 0.0, 0.12]
        np.testing.assert_allclose(scenes[kind].robot.tcp_offset[:3, 3], [0.0, 0.0, 0.12])
        assert {box.size[0] for box in scenes[kind].cell.obstacles if box.name in ("floor", "left")} == {0.45}
    assert scenes["pose_in_cubby"].queries[0].pose is not None
    for kind, extra in (("slot_40", 0.04), ("slot_60", 0.06)):  # the slot: the forearm's diameter and extra
        boxes = {box.name: box for box in scenes[kind].cell.obstacles}
        above, below = boxes["above"], boxes["below"]
        height = (above.xyz[2] - 0.5 * above.size[2]) - (below.xyz[2] + 0.5 * below.size[2])
        assert height == pytest.approx(2 * forearm_radius() + extra, abs=1e-9)
    assert forearm_radius() == pytest.approx(0.063)


def test_unknown_kinds_and_robots_are_refused():
    with pytest.raises(ValueError, match="kind must be one of"):
        generate("maze", 0)
    with pytest.raises(ValueError, match="UR e-Series"):
        generate("open", 0, robot=get_robot("li_4dof"))


def test_a_tiny_suite_writes_its_table(tmp_path):
    out = tmp_path / "free"
    rows = free_bench(out, count=1, kinds=("open", "gate"), workers=1, planning_time=10.0, progress=None)
    assert [(row["kind"], row["scene_seed"]) for row in rows] == [("open", 0), ("gate", 0)]
    with open(out / FREE_FILES[0]) as handle:
        table = list(csv.DictReader(handle))
    assert tuple(table[0]) == FREE_COLUMNS and len(table) == 2
    markdown = (out / FREE_FILES[1]).read_text()
    assert "| open | 1 |" in markdown and "| gate | 1 |" in markdown and "| all | 2 |" in markdown
    solved = rows[0]  # the open scene's witness is the straight move: solved
    assert solved["solved"] and solved["failure"] == ""
    assert solved["T_over_toppra"] > 0.99 and solved["min_distance_m"] > 0.0
    for row in rows:
        assert row["wall_s"] > 0 and row["cpu_s"] >= 0 and row["generation_s"] > 0
        assert row["solved"] or row["failure"].startswith(("PlanningError", "CollisionError"))


def test_the_command_line_refuses_bad_free_options_before_any_run(tmp_path, capsys):
    assert cli.main(["bench", "--suite", "free", "--count", "0", "--out", str(tmp_path / "f")]) == 2
    assert "count (--count) must be a whole number from 1" in capsys.readouterr().err
    assert not (tmp_path / "f").exists()
