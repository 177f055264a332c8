"""examples/check_descriptions.py: a folder of arm descriptions through the four planners and a
refused move through the table, on the shipped example description (examples/example_descriptions.yaml)."""

import json
import runpy
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from drake_traj import get_robot

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "examples" / "check_descriptions.py"
MANIFEST = ROOT / "examples" / "example_descriptions.yaml"
UR5E = get_robot("ur5e")  # the example arm's kinematics, from UR's DH table in closed form


@pytest.fixture(scope="module")
def script():
    return runpy.run_path(str(SCRIPT))


@pytest.fixture(scope="module")
def example_run(tmp_path_factory, script):
    """The script run on the shipped manifest in this process: (exit code, its JSON, the scenario file's variants)."""
    out = tmp_path_factory.mktemp("check")
    code = script["main"]([str(MANIFEST), "--jobs", "0", "--out", str(out), "--json", str(out / "outcomes.json"),
                           "--markdown", str(out / "table.md"), "--quiet"])
    text = (out / "example_arm.yaml").read_text()
    for tag in ("!CustomArm", "!QuinticConfig", "!SmoothWaypointsConfig", "!PajakConfig", "!FreeMotionConfig", "!Box"):
        text = text.replace(tag, "")
    return code, json.loads((out / "outcomes.json").read_text()), yaml.safe_load(text), (out / "table.md").read_text()


def quintic_time(points, velocity, acceleration) -> float:
    """Benotsmane et al.'s synchronised quintic moves: each move lasts the longest of its joints'
    15 |Δq| / (8 v) and sqrt(10 |Δq| / (√3 a)) [s]."""
    total = 0.0
    for a, b in zip(points[:-1], points[1:]):
        dq = np.abs(np.subtract(b, a))
        total += max(np.max(15 * dq / (8 * np.asarray(velocity))), np.max(np.sqrt(10 * dq / (np.sqrt(3) * np.asarray(acceleration)))))
    return total


def test_the_example_description_passes_every_variant(example_run):
    code, reports, scenarios, markdown = example_run
    assert code == 0
    (report,) = reports
    outcomes = {outcome["variant"]: outcome for outcome in report["outcomes"]}
    assert [outcome["status"] for outcome in outcomes.values()] == ["ok", "ok", "ok", "ok", "refused"]
    assert report["passed"] and all(outcome["passed"] for outcome in outcomes.values())
    assert "table" in outcomes["table"]["message"]
    quintic = scenarios["quintic"]
    points = [quintic["q_initial"], *quintic["planner"]["goals"]]
    assert outcomes["quintic"]["time"] == pytest.approx(
        quintic_time(points, quintic["planner"]["velocity_limit"], quintic["planner"]["acceleration_limit"]), abs=1e-6)
    assert "| example_arm | drake_traj | this repository | example_arm_description, `example_arm.urdf` | BSD-3-Clause | " \
           "`packages` | ok " in markdown


def test_the_task_is_placed_within_reach_with_the_table_below(example_run):
    _, _, scenarios, _ = example_run
    start = np.array(scenarios["pajak"]["q_initial"])
    corners = np.array(scenarios["pajak"]["planner"]["waypoints"])
    np.testing.assert_allclose(UR5E.tcp_pose(start), corners[-1], atol=1e-6)  # round the square back to the start
    sides = np.linalg.norm(np.diff(corners[:, :3], axis=0, append=corners[:1, :3]), axis=1)
    np.testing.assert_allclose(sides, sides[0], rtol=1e-6)  # a square, level, tool down
    assert np.ptp(corners[:, 2]) == 0 and corners[0, 2] > 0.1
    np.testing.assert_allclose(UR5E.tcp_pose(start)[3:], [np.pi, 0, 0], atol=1e-6)
    for goal in scenarios["quintic"]["planner"]["goals"]:  # the goals are the corners' joint solutions
        assert np.min(np.linalg.norm(UR5E.tcp_pose(goal)[:3] - corners[:, :3], axis=1)) < 1e-6
    goal = np.array(scenarios["table"]["planner"]["goals"][0])
    assert set(np.flatnonzero(goal - start)) <= {1, 2} and UR5E.tcp_pose(goal)[2] < -0.13  # shoulder and elbow turned: 0.1 R below
    free = np.array(scenarios["free"]["planner"]["poses"][0])
    assert np.hypot(*free[:2]) == pytest.approx(np.hypot(*corners[-1, :2]), abs=1e-5) and free[2] == corners[-1, 2]
    post = scenarios["free"]["cell"]["obstacles"][0]
    assert post["size"][2] > corners[0, 2]  # the post stands higher than the tool moves


def test_an_arm_that_cannot_be_read_fails_alone_in_its_process_with_its_error(tmp_path, script):
    shutil.copy(MANIFEST, tmp_path / "manifest.yaml")
    manifest = yaml.safe_load(MANIFEST.read_text())
    manifest["arms"][0]["robot"]["model_file"] = "missing.urdf"
    manifest["arms"][0]["variants"] = ["quintic", "table"]
    (tmp_path / "manifest.yaml").write_text(yaml.safe_dump(manifest))
    report = script["check_in_child"](tmp_path / "manifest.yaml", "example_arm", tmp_path)
    assert [outcome.status for outcome in report.outcomes] == ["error", "error"] and not report.passed
    assert report.outcomes[0].message == f"reading the arm: DrakeTrajError: robot.model_file {tmp_path / 'missing.urdf'} is not a file"
    text = script["table"]([report])
    assert "| example_arm | drake_traj | FAIL [1] | - | - | - | FAIL [1] |" in text
    assert text.endswith(f"[1] example_arm: error: {report.outcomes[0].message}")


@pytest.mark.parametrize("change, message", [
    (lambda m: m.pop("arms"), "the manifest must be a mapping with a non-empty list 'arms'"),
    (lambda m: m["arms"][0].update(label="two words"), "arms[0].label must be a plain unique name"),
    (lambda m: m["arms"][0].update(variants=["sideways"]), "arms[0].variants must be among"),
    (lambda m: m["arms"][0].update(colour="red"), "arms[0] has unknown keys ['colour']"),
])
def test_a_bad_manifest_exits_2_naming_the_arm_and_the_field(tmp_path, script, capsys, change, message):
    manifest = yaml.safe_load(MANIFEST.read_text())
    change(manifest)
    (tmp_path / "manifest.yaml").write_text(yaml.safe_dump(manifest))
    assert script["main"]([str(tmp_path / "manifest.yaml"), "--jobs", "0", "--out", str(tmp_path)]) == 2
    assert message in capsys.readouterr().err
