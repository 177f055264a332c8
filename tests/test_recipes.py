"""The recipes of docs/design.md ("Adding to drake_traj"), each followed on a toy example: a new
planner (its config, law, system and maker registered in one place), arm description format and
export format. (A new obstacle shape, one class: tests/test_cell.py.)"""

import gzip
import json
from dataclasses import dataclass, field

import numpy as np
import pytest

from drake_traj import QuinticConfig, SimulationResult, cli, get_robot, planners, simulate
from drake_traj.data import data_directory
from drake_traj.errors import DrakeTrajError
from drake_traj.planners import make_planner
from drake_traj.planners.base import TimeLawPlanner, joint_move_limits
from drake_traj.results import exports
from drake_traj.robots import model_files
from drake_traj.robots.chain_arm import ChainArm



# ---- a planner: config (with validate), law, system and make, registered in planners._MAKERS ----

@dataclass
class CubicConfig:
    """The toy planner's scenario entry: one cubic move q_start + (goal - q_start)(3u² - 2u³),
    u = t / T, to ``goal`` [rad], as short as the joint-move limits allow."""

    goal: list[float] = field(default_factory=list)
    velocity_limit: list[float] = field(default_factory=list)
    acceleration_limit: list[float] = field(default_factory=list)

    def validate(self, robot):
        if len(self.goal) != robot.num_joints:
            raise DrakeTrajError(f"goal must have {robot.num_joints} joint positions, got {len(self.goal)}",
                                 field=("goal",))
        joint_move_limits(robot, self.velocity_limit, self.acceleration_limit)
        return self


class CubicLaw:
    """The toy law (a :class:`~drake_traj.planners.laws.TimeLaw`): one cubic, q'' jumps at both ends."""

    def __init__(self, q_start, goal, velocity, acceleration):
        self.q_start, self.delta = np.asarray(q_start, float), np.asarray(goal, float) - q_start
        # the cubic's peaks: |q'| = 1.5 |Δ| / T at u = 1/2, |q''| = 6 |Δ| / T² at u = 0 and 1
        self.duration = float(max(np.max(1.5 * np.abs(self.delta) / velocity),
                                  np.max(np.sqrt(6 * np.abs(self.delta) / acceleration))))
        self.acceleration_jumps = np.array([0.0, self.duration])
        self.polynomial_breaks = np.array([0.0, self.duration])

    def sample(self, tau):
        T, u = self.duration, np.clip(tau / self.duration, 0.0, 1.0)
        inside = 0.0 < tau < T
        return (self.q_start + self.delta * (3 * u**2 - 2 * u**3), self.delta * (6 * u - 6 * u**2) / T * inside,
                self.delta * (6 - 12 * u) / T**2 * inside)

    def rates_at(self, tau):
        return self.sample(tau)[1:]


class CubicPlanner(TimeLawPlanner):
    """The toy system: a time-law planner around the cubic law."""

    def task_waypoints(self):
        return self.robot.tool_position((self.law.q_start + self.law.delta)[None, :])


def make_cubic(config, robot, q_initial):
    config.validate(robot)
    velocity, acceleration = joint_move_limits(robot, config.velocity_limit, config.acceleration_limit)
    return CubicPlanner(CubicLaw(q_initial, config.goal, velocity, acceleration), velocity, acceleration)


def test_a_planner_is_its_config_law_system_and_one_registry_entry(monkeypatch):
    monkeypatch.setitem(planners._MAKERS, CubicConfig, make_cubic)  # the one line a new planner adds
    robot = get_robot("ur10e")
    goal = robot.home_configuration + np.array([0.4, -0.3, 0.2, 0.0, -0.5, 0.6])
    planner = make_planner(CubicConfig(goal=goal.tolist()), robot, robot.home_configuration)
    assert planner.robot is robot

    plan = planner.plan()  # the law's pieces, as every time-law planner's plan
    t = np.linspace(0.0, plan.end_time(), 4001)
    qd = np.array([plan.EvalDerivative(time, 1).ravel() for time in t])
    qdd = np.array([plan.EvalDerivative(time, 2).ravel() for time in t])
    # the limits the move promises, at dense samples, and one joint at each of its limits
    assert np.all(np.abs(qd) <= robot.velocity_limits * (1 + 1e-9))
    assert np.all(np.abs(qdd) <= planner.acceleration_limit * (1 + 1e-9))
    assert np.isclose(max(np.max(np.abs(qd) / planner.velocity_limit), np.max(np.abs(qdd) / planner.acceleration_limit)),
                      1.0, atol=1e-3)

    result = simulate(planner)  # the preflight, the cell check and the closed loop, as for any planner
    assert result.succeeded, result.failure
    np.testing.assert_allclose(result.q_ref[-1], goal, atol=1e-9)
    np.testing.assert_allclose(result.q_meas[-1], goal, atol=1e-3)
    with pytest.raises(DrakeTrajError, match="goal must have 6 joint positions"):
        make_planner(CubicConfig(goal=[0.1]), robot, robot.home_configuration)


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
