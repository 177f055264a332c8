"""Where the package's data folders are: ``models/`` (our URDFs) and ``diagrams/`` (the scenarios).

Installed, they are the packages ``drake_traj.models`` and ``drake_traj.diagrams``; run from a
source tree that is not installed (``python -m drake_traj.cli`` in a checkout), the top-level
folders of the repository.
"""

from importlib import resources
from pathlib import Path

__all__ = ["data_directory"]


def data_directory(name: str) -> Path:
    """The folder of ``name`` ("models" or "diagrams")."""
    try:
        return Path(str(resources.files(f"drake_traj.{name}")))
    except ModuleNotFoundError:
        return Path(__file__).resolve().parents[1] / name
