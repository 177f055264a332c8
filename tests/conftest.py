"""Shared fixtures: one CLI run of the quintic scenario, reused by the output and browser tests."""

from pathlib import Path

import pytest

from drake_traj import cli

DIAGRAMS = Path(__file__).resolve().parents[1] / "diagrams"


@pytest.fixture(scope="session")
def quintic_run_dir(tmp_path_factory) -> Path:
    """Output directory of ``drake-traj run diagrams/quintic_ptp.yaml --out DIR``."""
    out = tmp_path_factory.mktemp("quintic_run")
    assert cli.main(["run", str(DIAGRAMS / "quintic_ptp.yaml"), "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def default_run_dir(tmp_path_factory) -> Path:
    """Output directory of ``drake-traj run --out DIR``: the default scenario, Pająk sim 3."""
    out = tmp_path_factory.mktemp("default_run")
    assert cli.main(["run", "--out", str(out)]) == 0
    return out
