"""Reading one scenario file, of one scenario or of named variants, into a validated
:class:`~drake_traj.scenario.scenario.Scenario`: the strict YAML check first
(:func:`~drake_traj.scenario.yaml_schema.checked_document`), then pydrake's ``yaml_load_typed``,
then :meth:`Scenario.validate <drake_traj.scenario.scenario.Scenario.validate>`, each error a
:class:`ScenarioError` located at its file, line, column and field."""

from pathlib import Path

from pydrake.common.yaml import yaml_load_typed

from drake_traj.errors import DrakeTrajError, did_you_mean
from drake_traj.scenario.scenario import Scenario, ScenarioSource
from drake_traj.scenario.yaml_schema import ScenarioError, checked_document, locate

__all__ = ["scenario_variants"]


def scenario_variants(path) -> list[str]:
    """The variant names of a scenario file; empty when the file is one scenario."""
    return list(checked_document(Path(path), Scenario)[1])


def read_scenario(path: Path, variant: str | None) -> Scenario:
    """The validated scenario of the file ``path`` (found already; ``variant``: the named child of
    a file of variants, may be None when the file is one scenario or has a single variant), its
    :attr:`~Scenario.source` set. Raises :class:`ScenarioError` naming the file, the line and the
    field."""
    root, variants, check = checked_document(path, Scenario)
    if variants:
        if variant is None and len(variants) == 1:
            variant = next(iter(variants))
        if variant not in variants:
            asked = "no variant was given" if variant is None else f"there is no variant {variant!r}"
            hint = did_you_mean(variant, variants)
            raise ScenarioError(f"{path}: {asked}; its variants are {list(variants)}{f'; {hint}' if hint else ''}")
        marks = check(variants[variant])
    elif variant is not None:
        raise ScenarioError(f"{path} holds one scenario, not variants; got variant {variant!r}")
    else:
        marks = check(root)
    try:
        scenario = yaml_load_typed(schema=Scenario, data=path.read_text(), child_name=variant)
    except RuntimeError as error:  # not expected after the check above; still one clear message
        raise ScenarioError(f"{path}: {error}") from None
    scenario.source = ScenarioSource(path, variant, marks)  # before validate(): a custom arm's file is found from it
    try:
        scenario.validate()
    except ValueError as error:
        field = error.field if isinstance(error, DrakeTrajError) else ()
        raise ScenarioError(locate(marks, path, field, str(error)), field=field) from None
    return scenario
