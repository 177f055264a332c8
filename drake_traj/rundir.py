"""Run folders: where ``drake-traj run`` writes, checked before any work, never mixed.

A run folder holds the files of one run and ``run.json``, the manifest that lists them. A folder
that holds an earlier run (a manifest, or the ``result.npz`` / ``metrics.json`` of a run written
before manifests) is not written into unless asked to overwrite, which first removes that run's
files, so nothing of two runs is ever mixed.
"""

import json
import os
from pathlib import Path

from drake_traj.errors import DrakeTrajError

__all__ = ["MANIFEST", "OutputError", "clear_run", "holds_a_run", "prepare_output", "write_manifest"]

MANIFEST = "run.json"
_RUN_FILES = ("result.npz", "metrics.json")  # a run written before manifests is recognised by these


class OutputError(DrakeTrajError):
    """An output folder cannot be used: names the folder and the reason."""


def holds_a_run(directory: Path) -> bool:
    """Whether ``directory`` holds the files of an earlier run."""
    return any((directory / name).exists() for name in (MANIFEST,) + _RUN_FILES)


def _check_writable(directory: Path) -> None:
    """The folder exists as a writable folder, or can be created: not a file, not below a file."""
    if directory.exists() and not directory.is_dir():
        raise OutputError(f"output folder {directory} is a file, not a folder")
    ancestor = directory
    while not ancestor.exists():
        if ancestor.parent == ancestor:
            break
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise OutputError(f"output folder {directory} cannot be created: {ancestor} is a file")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputError(f"output folder {directory} cannot be written: {ancestor} is not writable")


def prepare_output(directory, *, overwrite: bool = False) -> Path:
    """Check ``directory`` before a run (writable or creatable, not a file, not holding an earlier
    run unless ``overwrite``); with ``overwrite``, remove the earlier run's files. Creates the
    folder and returns it. Raises :class:`OutputError`."""
    directory = Path(directory)
    _check_writable(directory)
    if directory.is_dir() and holds_a_run(directory):
        if not overwrite:
            raise OutputError(f"output folder {directory} holds an earlier run (its {MANIFEST} or result.npz); "
                              "choose another --out, or pass --overwrite to replace that run")
        clear_run(directory)
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"output folder {directory} cannot be created: {error.strerror}") from None
    return directory


def clear_run(directory: Path) -> None:
    """Remove the files of the run in ``directory``: those its manifest lists (and the manifest),
    or for a run without a manifest, its result, metrics, figures and recording."""
    manifest = directory / MANIFEST
    if manifest.is_file():
        try:
            names = json.loads(manifest.read_text())["files"]
        except (ValueError, KeyError, TypeError):
            raise OutputError(f"{manifest} is damaged: cannot tell which files belong to the earlier run; "
                              "remove them by hand") from None
    else:
        names = [path.name for path in directory.iterdir()
                 if path.name in _RUN_FILES or path.suffix == ".png" or path.name == "meshcat.html"]
    for name in list(names) + [MANIFEST]:
        path = directory / Path(name).name  # never outside the folder
        if path.is_file():
            path.unlink()


def write_manifest(directory: Path, files, **details) -> Path:
    """Write ``run.json``: the run's file names and ``details`` (scenario, failure, ...)."""
    path = Path(directory) / MANIFEST
    path.write_text(json.dumps({"files": sorted(Path(name).name for name in files), **details}, indent=2))
    return path
