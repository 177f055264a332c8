"""Exports of a run's reference: a Drake trajectory, CSV, URScript and a ROS 2 JointTrajectory,
each read back and compared with the reference; refusals write nothing."""

import csv
import json
import runpy
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from drake_traj import SimulationResult, cli
from drake_traj.errors import Failure
from drake_traj.results.exports import UR_CONTROLLER_ARMS, ExportError, resample
from drake_traj.robots import ROBOT_NAMES, get_robot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def result(quintic_run_dir):
    return SimulationResult.load(quintic_run_dir)


def test_the_drake_trajectory_is_the_logged_reference(result):
    trajectory = result.reference_trajectory()
    values = np.array([trajectory.value(t).ravel() for t in result.t])
    rates = np.array([trajectory.EvalDerivative(t, 1).ravel() for t in result.t])
    np.testing.assert_allclose(values, result.q_ref, rtol=0, atol=1e-9)
    np.testing.assert_allclose(rates, result.qd_ref, rtol=0, atol=1e-9)


def test_the_example_replays_it_in_another_diagram(quintic_run_dir, capsys):
    error = runpy.run_path(str(EXAMPLES / "replay_reference.py"), run_name="example")["replay"](quintic_run_dir)
    assert "replayed 'quintic_ptp'" in capsys.readouterr().out
    assert error < 5e-3  # PD with gravity compensation only (measured 1 mrad); the station's feed-forward does 3.5e-5


def test_csv_reads_back_with_units_and_the_period(result, tmp_path):
    path = result.export(tmp_path / "reference.csv", "csv", period=0.002)
    comment, *rows = path.read_text().splitlines()
    assert comment.startswith("# drake-traj") and "cubic Hermite" in comment
    table = list(csv.reader(rows))
    header, data = table[0], np.array(table[1:], dtype=float)
    assert header[:2] == ["t [s]", "q1 [rad]"] and header[7] == "qd1 [rad/s]" and header[13] == "qdd1 [rad/s^2]"
    np.testing.assert_allclose(np.diff(data[:, 0]), 0.002, atol=1e-12)
    assert data[0, 0] == 0.0 and data[-1, 0] <= result.t[-1] < data[-1, 0] + 0.002
    every_other = slice(None, None, 2)  # each 2 ms sample is a logged 1 ms sample (10 significant digits)
    np.testing.assert_allclose(data[:, 1:7], result.q_ref[every_other][: len(data)], atol=2e-9)
    np.testing.assert_allclose(data[:, 7:13], result.qd_ref[every_other][: len(data)], atol=2e-9)
    np.testing.assert_allclose(data[:, 13:19], result.qdd_ref[every_other][: len(data)], atol=2e-9)


def test_urscript_streams_every_sample_with_servoj(result, tmp_path):
    path = result.export(tmp_path / "reference.script", "urscript", period=0.002, lookahead_time=0.05, gain=500)
    lines = path.read_text().splitlines()
    t, q, _, _ = resample(result, 0.002)
    servoj = [line for line in lines if line.strip().startswith("servoj(")]
    assert len(servoj) == round(t[-1] / 0.002) + 1 == len(q)  # duration / period + 1
    assert lines[0].startswith("def drake_traj_quintic_ptp():") and lines[-1] == "drake_traj_quintic_ptp()"
    assert lines[3].strip().startswith("movej(") and "stopj" in lines[-3]
    first = np.array(servoj[0].split("[")[1].split("]")[0].split(","), dtype=float)
    last = np.array(servoj[-1].split("[")[1].split("]")[0].split(","), dtype=float)
    np.testing.assert_allclose(first, result.q_ref[0], atol=1e-8)
    np.testing.assert_allclose(last, q[-1], atol=1e-8)
    assert all("t=0.002, lookahead_time=0.05, gain=500)" in line for line in servoj)


def test_ros2_joint_trajectory_structure(result, tmp_path):
    path = result.export(tmp_path / "trajectory.yaml", "ros2", period=0.01)
    message = yaml.safe_load(path.read_text())
    assert message["joint_names"] == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                                      "wrist_2_joint", "wrist_3_joint"]
    points = message["points"]
    t, q, qd, qdd = resample(result, 0.01)
    assert len(points) == len(t)
    for k in (0, 1, len(points) // 2, len(points) - 1):
        stamp = points[k]["time_from_start"]
        assert stamp["sec"] + 1e-9 * stamp["nanosec"] == pytest.approx(t[k], abs=1e-9)
        assert 0 <= stamp["nanosec"] < 1_000_000_000
        np.testing.assert_allclose(points[k]["positions"], q[k], atol=1e-12)
        np.testing.assert_allclose(points[k]["velocities"], qd[k], atol=1e-12)
        np.testing.assert_allclose(points[k]["accelerations"], qdd[k], atol=1e-12)


@pytest.mark.parametrize("change, pattern", [
    (dict(period=0.001), r"--period must be at least the UR controller's cycle"),
    (dict(lookahead_time=0.5), r"--lookahead-time must be in UR's range \[0.03, 0.2\]"),
    (dict(gain=50), r"--gain must be in UR's range \[100, 2000\]"),
    (dict(approach_speed=3.0), r"--approach-speed must be in \(0, 1\]"),
])
def test_urscript_options_out_of_range_are_refused(result, tmp_path, change, pattern):
    with pytest.raises(ExportError, match=pattern):
        result.export(tmp_path / "x.script", "urscript", **change)
    assert not (tmp_path / "x.script").exists()


def test_urscript_refuses_a_reference_beyond_the_ur10e(result, tmp_path):
    fast = SimulationResult(**{**vars(result), "qd_ref": result.qd_ref * 3.0})  # 3.2 rad/s on joint 1 > 2.094
    with pytest.raises(ExportError, match=r"joint \d \(\w+\) speed .* beyond the UR10e's"):
        fast.export(tmp_path / "x.script", "urscript")
    other = SimulationResult(**{**vars(result), "robot": "scara"})
    with pytest.raises(ExportError, match="URScript runs on a UR3e, UR5e, UR10e, UR16e, UR20 or UR30 controller; the run 'quintic_ptp' is on scara"):
        other.export(tmp_path / "x.script", "urscript")
    assert not (tmp_path / "x.script").exists()


def test_export_command(quintic_run_dir, tmp_path, capsys):
    out = tmp_path / "ref.csv"
    assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(out)]) == 0
    assert out.stat().st_size > 100_000
    before = out.read_bytes()
    assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(out)]) == 2
    assert "exists; pass --overwrite" in capsys.readouterr().err and out.read_bytes() == before
    assert cli.main(["export", str(tmp_path / "nowhere"), "--format", "ros2"]) == 2
    assert "no result file at" in capsys.readouterr().err
    assert cli.main(["export", str(quintic_run_dir), "--format", "urscript", "--gain", "5000", "--out", str(tmp_path / "x")]) == 2
    assert "--gain must be in UR's range" in capsys.readouterr().err and not (tmp_path / "x").exists()


def test_exports_join_the_run_and_leave_with_it(quintic_run_dir, tmp_path, capsys):
    # an export into the run's folder is listed in its manifest, so --overwrite removes it with the
    # run; an export never replaces the run's own files
    run = tmp_path / "run"
    shutil.copytree(quintic_run_dir, run)
    assert cli.main(["export", str(run), "--format", "urscript"]) == 0
    assert "reference.script" in json.loads((run / "run.json").read_text())["files"]
    for name in ("result.npz", "run.json", "joints.png"):
        assert cli.main(["export", str(run), "--format", "csv", "--out", str(run / name), "--overwrite"]) == 2
        assert "is one of the run's own files" in capsys.readouterr().err
    assert cli.main(["run", "quintic_ptp", "--out", str(run), "--overwrite"]) == 0
    assert not (run / "reference.script").exists() and (run / "result.npz").is_file()


@pytest.mark.parametrize("period, pattern", [
    (1e9, r"--period must be between 0.0001 s and half the logged motion"),
    (1e-9, r"--period must be between 0.0001 s"),
    (float("nan"), r"--period must be between"),
])
def test_export_period_outside_the_motion_is_refused(result, tmp_path, period, pattern):
    with pytest.raises(ExportError, match=pattern):
        result.export(tmp_path / "x.csv", "csv", period=period)
    assert not (tmp_path / "x.csv").exists()


def test_a_failed_or_non_finite_reference_is_not_exported(result, tmp_path):
    failed = SimulationResult(**{**vars(result), "failure": Failure("tracking", "the TCP was 99 mm from the reference")})
    for format in ("csv", "urscript", "ros2"):
        with pytest.raises(ExportError, match=r"the run 'quintic_ptp' failed \(the TCP was 99 mm .*--allow-failed"):
            failed.export(tmp_path / f"x.{format}", format)
    path = failed.export(tmp_path / "x.script", "urscript", allow_failed=True)
    assert path.read_text().startswith("# FAILED RUN: the TCP was 99 mm from the reference\n")
    q_ref = result.q_ref.copy()
    q_ref[100, 2] = np.nan
    broken = SimulationResult(**{**vars(result), "q_ref": q_ref})
    with pytest.raises(ExportError, match=r"not finite: q_ref at sample 100 is nan"):
        broken.export(tmp_path / "y.script", "urscript")
    assert not (tmp_path / "x.csv").exists() and not (tmp_path / "y.script").exists()


def test_every_export_names_the_robot(result, tmp_path):
    headers = {format: result.export(tmp_path / f"x{suffix}", format, period=0.01).read_text().splitlines()[:2]
               for format, suffix in (("csv", ".csv"), ("urscript", ".script"), ("ros2", ".yaml"))}
    assert "on the ur10e," in headers["csv"][0]
    assert "for a UR10e," in headers["urscript"][1]
    assert headers["ros2"][0].endswith("on the ur10e")


UR_ARMS = list(UR_CONTROLLER_ARMS)


@pytest.mark.parametrize("name", UR_ARMS)
def test_urscript_checks_each_ur_arm_against_its_own_ratings(result, tmp_path, name):
    robot = get_robot(name)
    model = "UR" + name[2:]
    speed, k = result.qd_ref.copy(), 2 * (len(result.t) // 4)  # an exported sample (every 2 ms of the 1 ms log)
    speed[k, 2] = 1.001 * robot.velocity_limits[2]  # joint 3, just above that arm's rated speed
    with pytest.raises(ExportError, match=rf"joint 3 \(elbow_joint\) speed {speed[k, 2]:.4f} rad/s at t = {result.t[k]:.3f} "
                                          rf"s is beyond the {model}'s {robot.velocity_limits[2]:.4f} rad/s"):
        SimulationResult(**{**vars(result), "robot": name, "effort_limit": robot.effort_limits,
                            "qd_ref": speed}).export(tmp_path / "x.script", "urscript")
    torque = np.zeros_like(result.tau)  # (the UR10e run's own torques are beyond a small arm's ratings)
    torque[7, 0] = -robot.effort_limits[0]  # the simulated drive saturated
    with pytest.raises(ExportError, match=rf"joint 1 \(shoulder_pan_joint\) torque -{robot.effort_limits[0]:.4f} N m "
                                          rf"at t = {result.t[7]:.3f} s is beyond the {model}'s"):
        SimulationResult(**{**vars(result), "robot": name, "effort_limit": robot.effort_limits,
                            "tau": torque}).export(tmp_path / "x.script", "urscript")
    assert not (tmp_path / "x.script").exists()


@pytest.mark.parametrize("robot", ["li_4dof", "my_own_arm", ""])
def test_urscript_refuses_an_arm_no_ur_controller_drives(result, tmp_path, robot):
    served = "(UR[0-9e]+(, | or )?)+"
    with pytest.raises(ExportError, match=rf"URScript runs on a {served} controller; the run 'quintic_ptp' is on "
                                          rf"{robot or 'an unknown robot'}$"):
        SimulationResult(**{**vars(result), "robot": robot}).export(tmp_path / "x.script", "urscript")
    assert not (tmp_path / "x.script").exists()


def test_the_ur_controller_arms_are_the_registered_e_series_arms():
    assert set(UR_CONTROLLER_ARMS) <= set(ROBOT_NAMES)
    assert {"ur3e", "ur5e", "ur10e", "ur16e", "ur20", "ur30"} <= set(UR_CONTROLLER_ARMS)
    assert not {"li_4dof", "scara"} & set(UR_CONTROLLER_ARMS)


@pytest.mark.parametrize("robot, ur_driver", [("ur10e", True), ("ur3e", True), ("puma_like", False), ("li_4dof", False)])
def test_the_ros2_hint_names_the_ur_driver_only_for_a_ur_arm(result, tmp_path, robot, ur_driver):
    hint = SimulationResult(**{**vars(result), "robot": robot}).export(tmp_path / "x.yaml", "ros2",
                                                                       period=0.01).read_text().splitlines()[1]
    assert ("/scaled_joint_trajectory_controller/" in hint) == ur_driver
    assert hint.startswith("# (ros2 topic pub --once /") and "/joint_trajectory " in hint


def test_urscript_refuses_a_run_whose_logged_limits_are_not_the_named_arms(result, tmp_path):
    """A run named after a UR arm but logged with another arm's torque limits (a custom arm that
    took the name, before ChainArm refused it) is not exported for that arm's controller."""
    puma = np.array([97.6, 186.4, 89.4, 24.2, 20.1, 21.3])
    with pytest.raises(ExportError, match=r"the run 'quintic_ptp' names the ur10e, but its torque limits \[97.6, .*\] N m "
                                          r"are not the UR10e's \[330.0, 330.0, 150.0, 56.0, 56.0, 56.0\] N m"):
        SimulationResult(**{**vars(result), "effort_limit": puma}).export(tmp_path / "x.script", "urscript")
    assert not (tmp_path / "x.script").exists()


def _read_only(monkeypatch, folder: Path) -> None:
    """Make ``folder`` behave as on a read-only file system (EROFS), root or not: access(2)
    says so, statvfs flags it, and creating or removing a file there fails."""
    import errno
    import os

    def erofs(path):
        return OSError(errno.EROFS, "Read-only file system", str(path))

    inside = lambda path: Path(os.path.abspath(path)).parent == folder  # noqa: E731
    access, statvfs, open_, unlink = os.access, os.statvfs, os.open, os.unlink

    class Flags:
        def __init__(self, real):
            self.real = real

        def __getattr__(self, name):
            return self.real.f_flag | os.ST_RDONLY if name == "f_flag" else getattr(self.real, name)

    monkeypatch.setattr(os, "access", lambda path, mode, **kw: False if Path(path) == folder and mode & os.W_OK
                        else access(path, mode, **kw))
    monkeypatch.setattr(os, "statvfs", lambda path: Flags(statvfs(path)) if Path(path) == folder else statvfs(path))

    def open_or_fail(path, flags, *args, **kw):
        if inside(path) and flags & (os.O_WRONLY | os.O_CREAT):
            raise erofs(path)
        return open_(path, flags, *args, **kw)

    def unlink_or_fail(path, *args, **kw):
        if inside(path):
            raise erofs(path)
        return unlink(path, *args, **kw)

    monkeypatch.setattr(os, "open", open_or_fail)
    monkeypatch.setattr(os, "unlink", unlink_or_fail)


@pytest.mark.parametrize("how", ["python", "cli"])
def test_an_export_into_a_read_only_folder_names_the_folder(result, quintic_run_dir, tmp_path, monkeypatch, capsys, how):
    """Was "internal error: OSError: [Errno 30] Read-only file system" (removing the temporary
    file that could not be made)."""
    folder = tmp_path / "readonly"
    folder.mkdir()
    _read_only(monkeypatch, folder)
    message = (f"--out {folder / 'ref.csv'}: output folder {folder} cannot be written: {folder} is on a read-only "
               "file system; nothing was written")
    if how == "cli":
        assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(folder / "ref.csv")]) == 2
        assert message in capsys.readouterr().err
    else:
        from drake_traj.results import OutputError

        with pytest.raises(OutputError) as caught:
            result.export(folder / "ref.csv", "csv")
        assert str(caught.value) == message
    monkeypatch.undo()
    assert list(folder.iterdir()) == []


def test_an_export_whose_folder_fails_while_writing_is_a_write_error(result, tmp_path, monkeypatch):
    """Writable when checked, read-only when written (remounted meanwhile): still an OutputError."""
    from drake_traj.results import OutputError, exports as export_module

    folder = tmp_path / "remounted"
    folder.mkdir()
    _read_only(monkeypatch, folder)
    monkeypatch.setattr(export_module, "check_writable", lambda directory: None)
    with pytest.raises(OutputError, match=rf"read-only file system while writing {folder / 'ref.csv'}; nothing was written"):
        result.export(folder / "ref.csv", "csv")
