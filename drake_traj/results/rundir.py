"""Run folders: where ``drake-traj run`` writes, checked before any work, never mixed.

A run folder holds the files of one run and ``run.json``, the manifest that lists them (exports
written into the folder are added to it). A folder that holds an earlier run (a manifest, or the
``result.npz`` / ``metrics.json`` of a run written before manifests) is not written into unless
asked to overwrite; the new run is written whole beside the earlier one and replaces it only
once complete on disk (:mod:`drake_traj.results.output`), so bad input, an interrupted start or a full
disk never costs the earlier run, and nothing of two runs is ever mixed. A folder that holds
other files, not a run (a bench, say), is never written into.
"""

import json
from pathlib import Path

from drake_traj.results.output import FOLDER_KINDS, OutputError, claim, folder_kind, write_file

__all__ = ["MANIFEST", "REFUSAL", "OutputError", "add_to_manifest", "claim_run_folder", "earlier_run", "estimated_size",
           "manifest_text", "run_files", "write_manifest"]

REFUSAL = "refusal.png"  # the picture of a refused motion, with a manifest naming the refusal

# the manifest, and the files a run written before manifests is recognised by
MANIFEST, *_RUN_FILES = FOLDER_KINDS["run"]
# [bytes] a run's folder, measured on quintic_ptp (6678 samples at 1 ms): result.npz 340 B and
# meshcat.html 380 B per sample, the figures 0.6 MiB; rounded up
_FIXED_SIZE, _SIZE_PER_SAMPLE = 2 * 2**20, 1024


def estimated_size(samples: int) -> int:
    """Roughly the bytes a run's folder takes with ``samples`` logged samples (an upper bound)."""
    return _FIXED_SIZE + _SIZE_PER_SAMPLE * int(samples)


def claim_run_folder(directory, *, overwrite: bool = False, samples: int = 0, command: str | None = None,
                     options=("--out", "--overwrite")):
    """Claim ``directory`` for a run before it starts (:func:`drake_traj.results.output.claim`): checked
    (:func:`drake_traj.results.output.check_folder`: writable, not a bench's, not other files, no earlier
    run unless ``overwrite``), locked against a second writer, with room for about ``samples``
    logged samples. Its ``replace()`` writes the run's files and replaces the earlier run."""
    return claim(directory, "run", overwrite=overwrite, earlier_files=run_files, estimate=estimated_size(samples),
                 command=command, options=options)


def run_files(directory: Path) -> list[str]:
    """The names of the files of the run in ``directory`` (manifest not included): those its
    manifest lists, or for a run without a manifest, its result, metrics, figures and recording."""
    manifest = directory / MANIFEST
    if manifest.is_file():
        try:
            names = json.loads(manifest.read_text())["files"]
            return [Path(str(name)).name for name in names]  # never outside the folder
        except (ValueError, KeyError, TypeError):
            raise OutputError(f"{manifest} is damaged: cannot tell which files belong to the earlier run; "
                              "remove them by hand") from None
    return [path.name for path in directory.iterdir()
            if path.name in _RUN_FILES or path.suffix == ".png" or path.name == "meshcat.html"]


def earlier_run(directory) -> dict | None:
    """What ``run.json`` of the run in ``directory`` holds (``files``: :func:`run_files`, and the
    rest of its manifest, if any) when the folder holds a run that is more than a refusal's
    picture; else None. A refusal is written beside such a run and never replaces it. The caller
    holds the folder's lock."""
    directory = Path(directory)
    if not directory.is_dir() or folder_kind(directory) != "run":
        return None
    files = run_files(directory)
    if not set(files) - {REFUSAL} and not any((directory / name).exists() for name in _RUN_FILES):
        return None  # an earlier refusal: a new one replaces it
    manifest = directory / MANIFEST
    details = json.loads(manifest.read_text()) if manifest.is_file() else {}
    return details | {"files": files}


def manifest_text(files, **details) -> str:
    """The text of ``run.json``: the run's file names and ``details`` (scenario, failure, ...)."""
    return json.dumps({"files": sorted(Path(name).name for name in files), **details}, indent=2)


def write_manifest(staging, files, **details) -> Path:
    """Write ``run.json`` (:func:`manifest_text`) into ``staging`` (a :class:`drake_traj.results.output.Staging`)."""
    return staging.write(MANIFEST, lambda path: path.write_text(manifest_text(files, **details)))


def add_to_manifest(directory: Path, name: str) -> None:
    """List the file ``name`` (e.g. an export) in the manifest of the run in ``directory``, so that
    replacing the run removes it too. The caller holds the folder's lock."""
    path = Path(directory) / MANIFEST
    details = json.loads(path.read_text())
    details["files"] = sorted(set(details["files"]) | {Path(name).name})
    write_file(path, json.dumps(details, indent=2), own_folder=directory, what="the manifest")
