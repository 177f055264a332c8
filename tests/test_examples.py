"""The examples run as written with no argument, from any folder: they default to the main job's
folder and, where it is missing, say which command writes it (exit 2, no traceback)."""

import runpy
import shutil
import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_replay_without_a_run_says_which_command_writes_one(tmp_path):
    done = subprocess.run([sys.executable, str(EXAMPLES / "replay_reference.py")], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert done.returncode == 2 and not done.stdout
    assert done.stderr == (f"replay_reference.py: no run in out or out/pajak_sim3 (in {tmp_path}): `drake-traj run "
                           "--out out` writes one; or give a run's folder: python examples/replay_reference.py RUN_DIR\n")


def test_replay_of_a_folder_without_a_run_names_it(tmp_path, capsys):
    main = runpy.run_path(str(EXAMPLES / "replay_reference.py"))["main"]
    assert main([str(tmp_path / "nothing")]) == 2
    assert capsys.readouterr().err.startswith(f"replay_reference.py: no result file at {tmp_path / 'nothing'}")


def test_replay_defaults_to_the_readmes_main_job_folder(quintic_run_dir, tmp_path, monkeypatch, capsys):
    shutil.copytree(quintic_run_dir, tmp_path / "out")  # where `drake-traj run --out out` writes
    monkeypatch.chdir(tmp_path)
    assert runpy.run_path(str(EXAMPLES / "replay_reference.py"))["main"]([]) == 0
    assert capsys.readouterr().out.startswith("replayed 'quintic_ptp'")
