"""What leaves the process (run folders, exports, benches) goes through one writer
(drake_traj.results.output): two writers of one folder, a full disk, a symbolic link out of the folder,
another run's or bench's folder, a read-only folder, a deleted working folder. In each, nothing
the user had is lost, nothing partial is left, and the message names the reason."""

import errno
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from drake_traj import SimulationResult, cli
from drake_traj.bench import run as bench
from drake_traj.cli import commands
from drake_traj.results import output

SIGNS = ("result.npz", "metrics.json", "run.json")


def state(folder: Path) -> dict:
    """Every file under ``folder`` (hidden ones too) by relative path, with its bytes."""
    return {str(path.relative_to(folder)): path.read_bytes() for path in sorted(folder.rglob("*")) if path.is_file()}


def copy_run(run: Path, folder: Path) -> dict:
    shutil.copytree(run, folder)
    return state(folder)


def fake_bench(folder: Path) -> dict:
    folder.mkdir()
    (folder / "bench.csv").write_text("task,planner\npaper,earlier\n")
    (folder / "bench.md").write_text("## the earlier bench\n")
    return state(folder)


@pytest.fixture
def nothing_runs(monkeypatch):
    """A run or bench that starts its work fails the test: the refusal must come before it."""
    def started(*args, **kwargs):
        raise AssertionError("the work started")
    monkeypatch.setattr(commands, "simulate", started)
    monkeypatch.setattr(bench, "tasks", started)


@pytest.fixture
def simulated(monkeypatch, quintic_run_dir):
    """``drake-traj run`` without its simulation (the quintic run's result, its wall time changed,
    instead): the writing alone."""
    loaded = SimulationResult.load(quintic_run_dir)
    result = SimulationResult(**{**vars(loaded), "wall_time": loaded.wall_time + 1.0})  # files unlike the earlier run's
    monkeypatch.setattr(commands, "simulate", lambda *args, **kwargs: result)


def mount_tmpfs(folder: Path, options: str) -> bool:
    """Mount a tmpfs at ``folder`` (root only); whether that worked."""
    folder.mkdir(exist_ok=True)
    if os.geteuid() != 0 or shutil.which("mount") is None:
        return False
    return subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True).returncode == 0


@pytest.fixture
def full_disk(tmp_path, monkeypatch):
    """``full_disk(size)``: a folder on a file system of ``size`` bytes (a tmpfs where mounting
    works; else every fsync, where the writer makes sure a file is on disk, fails with ENOSPC),
    without the writer's check of the free space, so that the disk really fills up while writing."""
    mounts = []

    def make(size: int) -> Path:
        folder = tmp_path / f"disk{len(mounts)}"
        if mount_tmpfs(folder, f"size={size}"):
            mounts.append(folder)
        else:
            def fsync(fd):
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            monkeypatch.setattr(os, "fsync", fsync)
        monkeypatch.setattr(output, "_check_space", lambda directory, needed: None)
        return folder

    yield make
    for folder in mounts:
        subprocess.run(["umount", str(folder)], check=True)


def test_two_runs_into_one_folder_one_wins_the_other_names_it(tmp_path, capsys):
    out = tmp_path / "run"
    first = subprocess.Popen([sys.executable, "-m", "drake_traj.cli", "run", "quintic_ptp", "--out", str(out), "--overwrite"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        deadline = time.monotonic() + 120
        while not (out / output.LOCK).exists():
            assert first.poll() is None and time.monotonic() < deadline, first.communicate()
            time.sleep(0.05)
        code = cli.main(["run", "quintic_ptp", "--out", str(out), "--overwrite"])
        err = capsys.readouterr().err
        assert code == cli.EXIT_BAD_INPUT, err
        assert f"output folder {out} is being written by another drake-traj process (pid {first.pid}: drake-traj run " \
               f"quintic_ptp --out {out} --overwrite" in err, err
        stdout, stderr = first.communicate(timeout=120)
    finally:
        first.kill()
    assert first.returncode == 0, stderr
    listed = json.loads((out / "run.json").read_text())["files"]
    assert sorted(path.name for path in out.iterdir()) == sorted(listed + ["run.json"])  # whole, and nothing else


def test_a_lock_left_by_a_dead_process_is_taken_over(tmp_path):
    out = tmp_path / "run"
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from drake_traj.results.output import claim; "
         f"held = claim({str(out)!r}, 'run', command='the holder'); print('held', flush=True); time.sleep(120)"],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "held\n"
        with pytest.raises(output.OutputError, match=rf"being written by another drake-traj process \(pid {holder.pid}: "
                                                     "the holder, since"):
            output.claim(out, "run")
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert (out / output.LOCK).read_text().startswith(f"pid {holder.pid}: the holder")  # left behind
    (out / ".drake-traj-staging-99999").mkdir()  # and half a run of a writer that died
    (out / ".drake-traj-staging-99999" / "result.npz").write_bytes(b"partial")
    with output.claim(out, "run", command="the next one"):
        assert (out / output.LOCK).read_text().startswith(f"pid {os.getpid()}: the next one")
        assert not (out / ".drake-traj-staging-99999").exists()
    assert list(out.iterdir()) == []  # the lock goes with its holder
    # a writer that died while moving its new files in: the earlier ones it had set aside are kept
    (out / ".drake-traj-replaced-99999").mkdir()
    (out / ".drake-traj-replaced-99999" / "result.npz").write_bytes(b"the earlier run")
    (out / ".drake-traj-staging-99999").mkdir()
    (out / ".drake-traj-staging-99999" / "metrics.json").write_bytes(b"the new run")
    cut_short = state(out)
    with pytest.raises(output.OutputError, match=rf"a writer that died \(pid 99999\) was replacing its content: the "
                                                 rf"earlier files are in {out}/.drake-traj-replaced-99999"):
        output.claim(out, "run", overwrite=True)
    assert state(out) == cut_short
    (out / ".drake-traj-staging-99999" / "metrics.json").unlink()  # all moved in: what was set aside goes
    with output.claim(out, "run", overwrite=True):
        assert list(out.iterdir()) == [out / output.LOCK]
    with output.claim(tmp_path / "new", "run"):
        assert (tmp_path / "new").is_dir()
    assert not (tmp_path / "new").exists()  # created by the claim, nothing written: removed


def test_a_full_disk_while_writing_a_run_keeps_the_earlier_run(simulated, quintic_run_dir, tmp_path, monkeypatch, capsys):
    out = tmp_path / "run"
    earlier = copy_run(quintic_run_dir, out)

    def full(self, path, **kwargs):
        Path(path).write_bytes(b"half a figure")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr("matplotlib.figure.Figure.savefig", full)
    assert cli.main(["run", "quintic_ptp", "--out", str(out), "--overwrite"]) == cli.EXIT_RUN_FAILED
    err = capsys.readouterr().err
    assert f"no space left on device while writing {out / 'joints.png'}; nothing was written: the earlier run in " \
           f"{out} is intact" in err and "internal error" not in err, err
    assert state(out) == earlier  # every file of the earlier run, nothing partial, no lock


def test_a_run_that_cannot_fit_is_refused_before_it_starts(nothing_runs, tmp_path, monkeypatch, capsys):
    out = tmp_path / "run"
    monkeypatch.setattr(output.shutil, "disk_usage", lambda path: shutil._ntuple_diskusage(10**9, 10**9 - 2**20, 2**20))
    assert cli.main(["run", "quintic_ptp", "--out", str(out)]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert re.search(rf"not enough space for {out}: about [2-9]\.\d MiB are needed, 1\.0 MiB are free there", err), err
    assert not out.exists()


def test_a_full_disk_while_writing_a_run_keeps_the_earlier_run_on_a_real_disk(simulated, quintic_run_dir, full_disk,
                                                                              capsys):
    out = full_disk(8 * 2**20) / "run"  # the earlier run takes 5.2 MB of the 8 MiB, the new one would too
    earlier = copy_run(quintic_run_dir, out)
    assert cli.main(["run", "quintic_ptp", "--out", str(out), "--overwrite"]) == cli.EXIT_RUN_FAILED
    err = capsys.readouterr().err
    assert re.search(rf"no space left on device while writing {out}/[a-z_]+\.(npz|json|png|html); nothing was written: "
                     rf"the earlier run in {out} is intact", err), err
    assert state(out) == earlier


def test_an_export_cut_short_by_a_full_disk_leaves_the_earlier_file(quintic_run_dir, full_disk, capsys):
    small_disk = full_disk(64 * 1024)
    out = small_disk / "reference.csv"
    out.write_text("the earlier export\n")
    assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(out), "--overwrite"]) == 1
    err = capsys.readouterr().err
    assert f"no space left on device while writing {out}; the earlier reference.csv is intact" in err, err
    assert state(small_disk) == {"reference.csv": b"the earlier export\n"}  # no truncated file beside it
    out.unlink()
    assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(out)]) == 1
    assert "no space left on device" in capsys.readouterr().err and state(small_disk) == {}
    # and the next export is not refused as "exists"


def test_a_symbolic_link_is_never_written_through(quintic_run_dir, tmp_path, capsys):
    run = tmp_path / "run_b"
    earlier = copy_run(quintic_run_dir, run)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "ref.csv").symlink_to(run / "result.npz")
    (tmp_path / "into_run").symlink_to(run)  # a folder that is a link to another run's folder
    for out, reason in ((mine / "ref.csv", f"is a symbolic link \\(to {run / 'result.npz'}\\)"),
                        (tmp_path / "into_run" / "metrics.json", r"is in the folder of a run")):
        assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(out), "--overwrite"]) == 2
        err = capsys.readouterr().err
        assert re.search(f"--out {out} {reason}", err), err
    assert state(run) == earlier and (mine / "ref.csv").is_symlink()


def test_an_export_into_another_runs_or_a_benchs_folder_is_refused(quintic_run_dir, tmp_path, capsys):
    run = tmp_path / "run_b"
    earlier = copy_run(quintic_run_dir, run)
    benched = fake_bench(tmp_path / "bench")
    for out in (run / "metrics.json", run / "new.csv", tmp_path / "bench" / "bench.csv"):
        assert cli.main(["export", str(quintic_run_dir), "--format", "csv", "--out", str(out), "--overwrite"]) == 2
        kind = "bench" if "bench" in out.parent.name else "run"
        assert f"--out {out} is in the folder of a {kind} ({out.parent}); a file is never written into another " \
               f"{kind}'s folder" in capsys.readouterr().err
    assert state(run) == earlier and state(tmp_path / "bench") == benched
    with pytest.raises(output.OutputError, match="is in the folder of a run"):  # from Python too
        SimulationResult.load(quintic_run_dir).export(run / "new.csv", "csv")


def test_a_bench_never_goes_into_a_run_nor_over_an_earlier_bench_unasked(nothing_runs, quintic_run_dir, tmp_path, capsys):
    run = tmp_path / "run"
    earlier = copy_run(quintic_run_dir, run)
    assert cli.main(["bench", "--out", str(run), "--count", "0", "--workers", "1", "--overwrite"]) == 2
    assert f"--out {run}: output folder {run} holds a run (its run.json and result.npz and metrics.json); a bench is " \
           "never written into a run's folder" in capsys.readouterr().err
    benched = fake_bench(tmp_path / "bench")
    assert cli.main(["bench", "--out", str(tmp_path / "bench"), "--count", "0", "--workers", "1"]) == 2
    assert "holds an earlier bench (its bench.csv and bench.md); choose another --out, or pass --overwrite" in \
           capsys.readouterr().err
    assert state(run) == earlier and state(tmp_path / "bench") == benched
    assert cli.main(["run", "quintic_ptp", "--out", str(tmp_path / "bench"), "--overwrite"]) == 2
    assert "holds a bench (its bench.csv and bench.md); a run is never written into a bench's folder" in \
           capsys.readouterr().err


def test_a_bench_replaces_an_earlier_bench_with_overwrite(tmp_path, capsys):
    out = tmp_path / "bench"
    fake_bench(out)
    table = bench.bench(out, count=0, repeats=1, workers=1, planners=("quintic_stop",), overwrite=True, progress=None)
    assert sorted(path.name for path in out.iterdir()) == ["bench.csv", "bench.md", "bench.png"]
    assert (out / "bench.csv").read_text().splitlines()[1].startswith("paper,quintic_stop,True,")
    assert len(table) == 1 and "earlier" not in (out / "bench.md").read_text()


@pytest.mark.parametrize("below", ["", "bench"], ids=["the folder", "a folder to create in it"])
def test_a_read_only_folder_is_refused_before_the_bench_runs(nothing_runs, tmp_path, capsys, below):
    folder = tmp_path / "read_only"
    if not mount_tmpfs(folder, "ro,size=64k"):
        folder.chmod(0o555)
        if os.access(folder, os.W_OK):
            pytest.skip("cannot make a read-only folder here (root without mount)")
    out = folder / below
    try:
        assert cli.main(["bench", "--out", str(out), "--count", "0", "--workers", "1"]) == 2
        err = capsys.readouterr().err
        assert f"--out {out}: output folder {out} cannot be" in err, err
        assert "on a read-only file system" in err or "not writable (permission denied)" in err, err
    finally:
        if os.path.ismount(folder):
            subprocess.run(["umount", str(folder)], check=True)
        folder.chmod(0o755)


def test_a_deleted_working_folder_is_named(nothing_runs, tmp_path, monkeypatch, capsys):
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    assert cli.main(["run", "quintic_ptp"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "the working folder no longer exists (it was deleted or moved while in use)" in err, err
