"""Shared fixtures (CLI runs of the quintic scenario and of the default one, made once and read by
several test files) and the suite's order.

The suite runs on every core (pytest-xdist; ``addopts`` in pyproject.toml), a whole test file to a
worker (``--dist loadfile``): a file's module fixtures are made once, and tests/test_docs.py's page
runs stay in one process. The files that take longest start first (``LONGEST_FIRST``), so that no
worker is left running one of them alone at the end. ``pytest -n0`` runs the suite in one process.
"""

import fcntl
import os
from pathlib import Path

import pytest

from drake_traj import cli

TESTS = Path(__file__).resolve().parent
DIAGRAMS = TESTS.parent / "diagrams"

# Measured in one process (the whole suite, on 2 cores): test_docs.py 127 s (its pages' commands run
# two at a time), test_soak.py about 120 s (its 100 seeded tasks), test_speed_override.py 95 s,
# test_bench.py 80 s, test_browser.py 78 s (a live view at a tenth of real time), test_bad_input.py
# 67 s; every other file under 25 s.
LONGEST_FIRST = ("test_docs.py", "test_soak.py", "test_speed_override.py", "test_bench.py", "test_browser.py",
                 "test_bad_input.py")


def pytest_collection_modifyitems(items):
    """The files of ``LONGEST_FIRST`` first, in that order; the others after, in their own order."""
    rank = {TESTS / name: position for position, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path, len(rank)))


def interrupt_inside_compiled_code(*_):
    """Raise what a Ctrl-C or SIGTERM handled as numba's compiled code returns raises: a
    SystemError ("returned a result with an exception set") caused by the KeyboardInterrupt.
    Takes and ignores any arguments, to stand in for a function."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as stop:
        raise SystemError("CPUDispatcher(<function kernel>) returned a result with an exception set") from stop


def made_once(tmp_path_factory, name: str, make) -> Path:
    """The folder ``name`` filled by ``make(folder)`` once per test session, read-only for the
    tests. The workers of a parallel run share it: the first to ask makes it while the others
    wait on a lock, then all read the same folder (a partly made folder is never used: it is
    made under another name and renamed when complete)."""
    if "PYTEST_XDIST_WORKER" not in os.environ:  # one process
        folder = tmp_path_factory.mktemp(name)
        make(folder)
        return folder
    shared = tmp_path_factory.getbasetemp().parent  # the session's folder, above each worker's own
    folder = shared / name
    with open(shared / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
        if not folder.is_dir():
            partial = shared / f"{name}.{os.environ['PYTEST_XDIST_WORKER']}"
            partial.mkdir()
            make(partial)
            partial.rename(folder)
    return folder


def run_into(*argv: str):
    """``make`` for :func:`made_once`: ``drake-traj run ARGV --out FOLDER``, which must succeed."""
    def make(folder: Path) -> None:
        assert cli.main(["run", *argv, "--out", str(folder)]) == 0
    return make


@pytest.fixture(scope="session")
def quintic_run_dir(tmp_path_factory) -> Path:
    """Output directory of ``drake-traj run diagrams/quintic_ptp.yaml --out DIR``."""
    return made_once(tmp_path_factory, "quintic_run", run_into(str(DIAGRAMS / "quintic_ptp.yaml")))


@pytest.fixture(scope="session")
def default_run_dir(tmp_path_factory) -> Path:
    """Output directory of ``drake-traj run --out DIR``: the default scenario, Pająk sim 3."""
    return made_once(tmp_path_factory, "default_run", run_into())
