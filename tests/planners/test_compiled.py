"""drake_traj.compiled: numba's on-disk cache where it can write one, compilation in each process
where it cannot (the kernels of the arms and of the Pająk 2024 law use it), and a cache that follows
an edit of the modules a cached kernel calls."""

import importlib.util
import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import drake_traj

SOURCE = "from drake_traj.compiled import compiled\n\n\n@compiled\ndef twice(x):\n    return 2.0 * x\n"


def load(path):
    spec = importlib.util.spec_from_file_location(f"kernel_{abs(hash(str(path)))}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_cached_where_a_cache_directory_is_writable(tmp_path):
    (tmp_path / "kernel.py").write_text(SOURCE)
    twice = load(tmp_path / "kernel.py").twice
    assert twice(1.5) == 3.0
    assert twice.stats.cache_path == str(tmp_path / "__pycache__")
    assert list((tmp_path / "__pycache__").glob("kernel.twice-*.nbi"))


def test_compiled_without_a_cache_when_no_directory_is_writable(tmp_path):
    # numba finds no cache directory for a function whose source file it cannot see, as for a
    # read-only installation without a writable user cache: compiled anyway, not cached
    (tmp_path / "kernel.py").write_text(SOURCE)
    module = load(tmp_path / "kernel.py")
    (tmp_path / "kernel.py").unlink()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        twice = module.compiled(module.twice.py_func)
    assert twice(1.5) == 3.0
    assert twice.stats.cache_path is None


PROBE = """
import numpy as np
from drake_traj.robots import UR10E, ur10e
from drake_traj.robots.chain import SerialChain
from drake_traj.robots.compiled_kinematics import task_kinematics_into
q = np.array(ur10e.HOME)
chain = SerialChain.from_dh(np.column_stack([ur10e.DH_D, ur10e.DH_A, ur10e.DH_ALPHA, np.zeros(6)]))
pose = np.empty(6)
task_kinematics_into(chain.packed(), q, np.zeros(6), np.eye(4), pose, np.empty((6, 6)), np.empty(6))
print(UR10E.kinematics(q, np.zeros(6))[0][0], pose[0])
"""


def test_an_edit_of_a_module_that_cached_kernels_call_recompiles_them(tmp_path):
    """numba checks a cached function against its own file only: the UR closed form and the
    generic chain (cached in their modules) call task_space's compiled code, and the dispatcher
    calls both; an edit of task_space.py must reach them in the next process (a copy of the
    package with its own cache: the flange x moved by 1 m)."""
    package = tmp_path / "package"
    shutil.copytree(Path(drake_traj.__file__).parent, package / "drake_traj",
                    ignore=shutil.ignore_patterns("__pycache__"))
    environment = {**os.environ, "PYTHONPATH": str(package), "NUMBA_CACHE_DIR": str(tmp_path / "cache")}

    def flange_x() -> list[float]:
        out = subprocess.run([sys.executable, "-c", PROBE], env=environment, cwd=tmp_path, capture_output=True,
                             text=True, check=True).stdout
        return [float(value) for value in out.split()]

    before = flange_x()  # compiled and cached
    assert before == pytest.approx([-0.17415, -0.17415], abs=1e-12) and any((tmp_path / "cache").rglob("*.nbi"))
    source = package / "drake_traj" / "robots" / "task_space.py"
    edited = source.read_text().replace("pose[0], pose[1], pose[2] = p0, p1, p2 + 0.0",
                                        "pose[0], pose[1], pose[2] = p0 + 1.0, p1, p2 + 0.0")
    assert edited != source.read_text()
    source.write_text(edited)
    assert flange_x() == pytest.approx([0.82585, 0.82585], abs=1e-12)
