"""The scenarios shipped with the package (the files of ``diagrams/``) and finding a scenario by
its file or its name: :func:`load_scenario` takes either, as ``drake-traj run`` does
(:func:`find_scenario`, then the file read by :func:`~drake_traj.scenario.loading.read_scenario`).
The shipped scenarios' names, robots and descriptions come from :mod:`drake_traj.catalogue`
(:func:`shipped_scenarios`, read without building anything), which also says which copy of the
files runs (:func:`shipped_copy`)."""

from pathlib import Path

from drake_traj.catalogue import ShippedScenario, shipped_copy, shipped_directory, shipped_scenarios
from drake_traj.errors import did_you_mean
from drake_traj.validation import instance_of, path_argument
from drake_traj.scenario.loading import read_scenario
from drake_traj.scenario.scenario import Scenario
from drake_traj.scenario.yaml_schema import ScenarioError

__all__ = [
    "DEFAULT_SCENARIO", "ShippedScenario", "default_scenario_path", "find_scenario", "load_scenario", "shipped_copy",
    "shipped_directory", "shipped_scenarios",
]

DEFAULT_SCENARIO = ("pajak.yaml", "sim3")  # what ``drake-traj run`` runs when given no scenario


def default_scenario_path() -> Path:
    """The scenario file ``drake-traj run`` uses when none is given (its variant: ``sim3``)."""
    return shipped_directory() / DEFAULT_SCENARIO[0]


def find_scenario(reference: str, variant: str | None = None) -> tuple[Path, str | None]:
    """(file, variant) of a scenario given as a path, or as the name of a shipped scenario
    (``pajak_sim3``; with ``variant``, that variant of its file: ``pajak_sim3``, ``"sim1"`` is
    ``pajak_sim1``) or of a shipped file (``pajak``, with ``variant``)."""
    path = Path(reference)
    try:
        return _find_scenario(path, reference, variant)
    except OSError as error:  # a name too long, ...
        raise ScenarioError(f"scenario file {str(path)[:80]}{'...' if len(str(path)) > 80 else ''} cannot be "
                            f"used: {error.strerror}") from None


def _find_scenario(path: Path, reference: str, variant: str | None) -> tuple[Path, str | None]:
    if path.is_file():
        return path, variant
    if path.is_symlink() and not path.exists():
        raise ScenarioError(f"scenario file {path} is a broken link or a loop of links")
    if path.exists() and not path.is_dir():
        raise ScenarioError(f"scenario file {path} is not a regular file (a device or a pipe)")
    # a bare name is looked up among the shipped scenarios even when a folder of that name is
    # here (e.g. an earlier run's --out quintic_ptp)
    bare_name = path.suffix not in (".yaml", ".yml") and len(path.parts) == 1
    if path.is_dir() and not (bare_name and _is_shipped_name(reference)):
        raise ScenarioError(f"scenario file {path} is a folder, not a scenario file")
    if not bare_name:
        where = "" if path.is_absolute() else _in_working_folder()
        raise ScenarioError(f"scenario file {path} not found{where}{_shipped_alternative(path, variant)}")
    shipped = shipped_scenarios()
    for entry in shipped:
        if entry.name == reference:  # with a variant: that variant of the scenario's file
            return entry.path, entry.variant if variant is None else variant
    stem = shipped_directory() / f"{reference}.yaml"
    if stem.is_file():
        return stem, variant
    known = dict.fromkeys([entry.name for entry in shipped] + [entry.path.stem for entry in shipped])  # names, then files
    hint = did_you_mean(reference, known)
    raise ScenarioError(f"no scenario file {reference!r} and no shipped scenario of that name; shipped: "
                        f"{', '.join(entry.name for entry in shipped)} (drake-traj list){f'; {hint}' if hint else ''}")


def _in_working_folder() -> str:
    """`` in <the working folder>``, where a relative path was looked for ("" if it is gone)."""
    try:
        return f" in {Path.cwd()}"
    except OSError:  # the working folder was deleted
        return ""


def _shipped_alternative(path: Path, variant: str | None) -> str:
    """For a scenario ``path`` that is not there (``diagrams/pajak.yaml`` outside the checkout): how
    to run the shipped file of that name (by its file name, ``.yaml`` or not), or ""."""
    file = shipped_directory() / (path.name if path.suffix in (".yaml", ".yml") else f"{path.name}.yaml")
    entries = [entry for entry in shipped_scenarios() if entry.path.name == file.name]
    if not entries:
        return ""
    chosen = [entry for entry in entries if variant is None or entry.variant == variant]
    if len(chosen) == 1:
        name = chosen[0].name
        return f"; the shipped scenario of that name runs as `drake-traj run {name}` (Python: load_scenario({name!r}))"
    name = next((entry.name for entry in entries if (file.name, entry.variant) == DEFAULT_SCENARIO), entries[0].name)
    return (f"; the shipped file of that name holds {', '.join(entry.name for entry in entries)}: run one by its "
            f"name, e.g. `drake-traj run {name}` (Python: load_scenario({name!r}))")


def _is_shipped_name(reference: str) -> bool:
    """True when ``reference`` names a shipped scenario or a shipped file."""
    return (shipped_directory() / f"{reference}.yaml").is_file() or any(
        entry.name == reference for entry in shipped_scenarios())


def load_scenario(name_or_path, variant: str | None = None) -> Scenario:
    """Read and validate a scenario: a YAML file, or the name of a shipped scenario
    (``"quintic_ptp"``, ``"pajak_sim3"``) or of a shipped file (``"pajak"``, with ``variant``),
    as ``drake-traj run`` takes it (:func:`find_scenario`). ``variant``: the named child of a file
    of variants; it may be left out when the file is one scenario or has a single variant.

    Raises :class:`ScenarioError` (a ValueError) naming the file, the line and the field (its
    ``field`` attribute holds the field's path).
    """
    reference = path_argument(name_or_path, "name_or_path")
    if variant is not None:
        instance_of(variant, str, "variant")
    path, variant = find_scenario(str(reference), variant)
    return read_scenario(path, variant)
