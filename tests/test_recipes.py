"""The recipes of docs/design.md ("Adding to drake_traj"), each followed on a toy example: a new
arm description format, export format and planner are each one class or folder, registered in
one place. (A new obstacle shape: tests/test_cell.py.)"""

import gzip
import json

import numpy as np
import pytest

from drake_traj import QuinticConfig, SimulationResult, cli, simulate
from drake_traj.data import data_directory
from drake_traj.planners import make_planner
from drake_traj.results import exports
from drake_traj.robots import model_files
from drake_traj.robots.chain_arm import ChainArm

START = np.array([-np.pi / 2, -np.pi / 2, -3 * np.pi / 4, -np.pi / 4, np.pi / 2, np.pi / 4])  # [rad]


class GzippedUrdf(model_files.ModelFormat):
    """The toy format: a URDF file compressed with gzip (``.urdf.gz``)."""

    def urdf_text(self, path, parser, arguments, field, label):
        return gzip.decompress(path.read_bytes()).decode()


def test_an_arm_format_is_one_class_and_its_entry(tmp_path, monkeypatch):
    plain = data_directory("models") / "ur5e.urdf"
    packed = tmp_path / "arm.urdf.gz"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    monkeypatch.setitem(model_files.MODEL_FORMATS, ".gz", GzippedUrdf())

    arms = [ChainArm.from_model_file(path, name=f"arm_{k}", base_frame="base", tool_frame="tool0",
                                     acceleration_limits=1.4, home=START) for k, path in enumerate((plain, packed))]
    rng = np.random.default_rng(7)
    for q in rng.uniform(-np.pi, np.pi, size=(20, 6)):  # the same kinematics from both files
        np.testing.assert_allclose(arms[1].tcp_pose(q), arms[0].tcp_pose(q), atol=1e-12)
    for limit in ("lower_limits", "upper_limits", "velocity_limits", "effort_limits"):  # the file's limits read
        np.testing.assert_array_equal(getattr(arms[1], limit), getattr(arms[0], limit))

    config = QuinticConfig(goals=[(START + 0.3).tolist()])
    result = simulate(make_planner(config, arms[1], START))  # the station parses the packed file too
    assert result.succeeded, result.failure
    np.testing.assert_allclose(result.q_meas[-1], START + 0.3, atol=1e-3)


def test_without_its_entry_the_toy_format_is_not_read(tmp_path):
    packed = tmp_path / "arm.urdf.gz"
    packed.write_bytes(gzip.compress((data_directory("models") / "ur5e.urdf").read_bytes()))
    assert isinstance(model_files.model_format(packed), model_files.ModelFormat)
    assert model_files.model_format(packed).urdf_text(packed, None, {}, ("model_file",), "model_file") is None


class JsonReference(exports.ExportFormat):
    """The toy export format: the resampled reference as JSON, {"t": [...], "q": [[...], ...]}."""

    suffix = ".json"

    def check_options(self, options):
        if options.period < 0.001:
            raise exports.ExportError(f"--period must be at least the log's 0.001 s for JSON, got {options.period}")

    def text(self, result, t, q, qd, qdd, options):
        return json.dumps({"t": t.tolist(), "q": q.tolist()})


def test_an_export_format_is_one_class_and_its_entry(quintic_run_dir, tmp_path, monkeypatch):
    monkeypatch.setitem(exports.FORMATS, "json", JsonReference())
    out = tmp_path / "reference.json"
    assert cli.main(["export", str(quintic_run_dir), "--format", "json", "--period", "0.002", "--out", str(out)]) == 0
    written = json.loads(out.read_text())
    result = SimulationResult.load(quintic_run_dir)
    t, q = np.array(written["t"]), np.array(written["q"])
    np.testing.assert_allclose(t, 0.002 * np.arange(len(t)), atol=1e-12)
    assert t[-1] <= result.t[-1] < t[-1] + 0.002
    # every other logged sample (1 ms log), through which the exported spline passes
    np.testing.assert_allclose(q, result.q_ref[::2][:len(t)], atol=1e-12)
    # its own option check runs before anything is written
    assert cli.main(["export", str(quintic_run_dir), "--format", "json", "--period", "0.0005",
                     "--out", str(tmp_path / "fine.json")]) == cli.EXIT_BAD_INPUT
    assert not (tmp_path / "fine.json").exists()
