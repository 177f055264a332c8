"""The shipped scenarios as a catalogue: each one's name, file, variant, description and robot,
read from the YAML files of ``diagrams/`` without building anything (no Drake, no robot models),
so that ``drake-traj list`` answers at once and a scenario's name is found quickly.

Reading a scenario whole (checked, its robot and cell built) is
:func:`drake_traj.scenario.load_scenario`; a catalogue entry is what the same file says, read as
plain YAML: a file of one scenario names fields of a scenario (:data:`SCENARIO_FIELDS`) at its top
level, a file of variants names its variants there (keys starting with ``_`` hold shared YAML
anchors), as :func:`drake_traj.scenario.yaml_schema.checked_document` reads it.
"""

import functools
from dataclasses import dataclass
from pathlib import Path

import yaml

from drake_traj.data import data_directory

__all__ = ["SCENARIO_FIELDS", "ShippedScenario", "shipped_copy", "shipped_directory", "shipped_scenarios"]

# the fields of drake_traj.scenario.Scenario, in order (tests/test_cli_conventions.py holds them equal)
SCENARIO_FIELDS = ("name", "description", "robot", "q_initial", "planner", "cell", "controller", "plant", "simulator",
                   "log_period", "speed_override", "tracking_tolerance", "settle_time", "max_duration")
DEFAULT_NAME = "unnamed"  # a scenario's name when its file gives none (Scenario.name's default)
DEFAULT_ROBOT = "ur10e"  # its robot when the file names none (Scenario.robot's default)


def shipped_directory() -> Path:
    """The folder of the scenario files shipped with the package (``diagrams/``)."""
    return data_directory("diagrams")


def shipped_copy() -> str:
    """Which copy of the shipped scenario files runs, said by ``drake-traj list -v`` and ``show
    --where``: a source tree's ``diagrams/`` (a checkout, an editable install), where an edit
    changes what runs, or the installed package's, which a checkout's ``diagrams/`` does not change."""
    directory = shipped_directory()
    if (directory.parent / "pyproject.toml").is_file():
        return f"this source tree's diagrams/ ({directory}; an edit there changes what runs)"
    return (f"the installed package ({directory}; a checkout's diagrams/ is not read: copy a scenario with "
            "drake-traj show NAME > my_task.yaml, edit the copy and run it by its path)")


@dataclass(frozen=True)
class ShippedScenario:
    """A scenario shipped with the package: its name, file, variant (None for a file of one
    scenario), one-line description and robot (a robot's name, or an arm of one's own as
    ``puma560 (DhArm)``: :func:`~drake_traj.robots.custom.robot_label`)."""

    name: str
    path: Path
    variant: str | None
    description: str
    robot: str


def shipped_scenarios() -> list[ShippedScenario]:
    """Every scenario of the shipped files, in file order (files by name). Read once per version
    of the files (each file's modification time and size). A shipped file that is not YAML
    raises a ValueError naming it."""
    versions = tuple((path, path.stat().st_mtime_ns, path.stat().st_size)
                     for path in sorted(shipped_directory().glob("*.yaml")))
    return list(_entries(versions))


@functools.lru_cache(maxsize=4)
def _entries(versions: tuple[tuple[Path, int, int], ...]) -> tuple[ShippedScenario, ...]:
    """The :class:`ShippedScenario` entries of the files ``versions`` ((path, mtime, size), in order)."""
    entries = []
    for path, _, _ in versions:
        try:
            document = yaml.load(path.read_text(encoding="utf-8"), Loader=_TaggedLoader)
        except (yaml.YAMLError, UnicodeDecodeError) as error:
            raise ValueError(f"shipped scenario file {path} cannot be read: {error}") from None
        if not isinstance(document, dict):
            raise ValueError(f"shipped scenario file {path} is not a mapping of fields or of variants")
        if set(document) & set(SCENARIO_FIELDS):
            variants = {None: document}
        else:
            variants = {key: value for key, value in document.items() if not str(key).startswith("_")}
        for variant, fields in variants.items():
            fields = fields if isinstance(fields, dict) else {}
            entries.append(ShippedScenario(str(fields.get("name", DEFAULT_NAME)), path, variant,
                                           str(fields.get("description", "")), _robot_label(fields.get("robot", DEFAULT_ROBOT))))
    return tuple(entries)


def _robot_label(robot) -> str:
    """A ``robot:`` field as a list shows it: a robot's name, or an arm of one's own as its name
    and its tag (``puma560 (DhArm)``)."""
    if isinstance(robot, _Tagged):
        name = robot.value.get("name") if isinstance(robot.value, dict) else None
        return f"{name} ({robot.tag})" if name else robot.tag
    return str(robot)


@dataclass(frozen=True)
class _Tagged:
    """A YAML node with a type tag (``!DhArm {...}``, ``!QuinticConfig {...}``): the tag without
    its ``!`` and the plain value."""

    tag: str
    value: object


class _TaggedLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """YAML's safe loader (libyaml's where installed) that keeps the type tags of a scenario file."""


def _construct_tagged(loader, suffix: str, node) -> _Tagged:
    if isinstance(node, yaml.MappingNode):
        value = loader.construct_mapping(node, deep=True)
    elif isinstance(node, yaml.SequenceNode):
        value = loader.construct_sequence(node, deep=True)
    else:
        value = loader.construct_scalar(node)
    return _Tagged(suffix, value)


_TaggedLoader.add_multi_constructor("!", _construct_tagged)
