"""The package's structure: no import cycle, dependencies pointing one way, configs YAML can type,
and a public API that imports."""

import ast
import dataclasses
import importlib
from pathlib import Path

import pytest

import drake_traj
from drake_traj.planners import PLANNER_CONFIGS
from drake_traj.scenario import Scenario

PACKAGE = Path(drake_traj.__file__).resolve().parent


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(path): path for path in PACKAGE.rglob("*.py")}


def imports_of(name: str) -> list[tuple[str, bool]]:
    """(imported drake_traj module, imported at module level) for every import in ``name``."""
    tree = ast.parse(MODULES[name].read_text())
    top_level = {id(node) for node in tree.body}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            targets = [f"{node.module}.{alias.name}" if f"{node.module}.{alias.name}" in MODULES else node.module
                       for alias in node.names]
        else:
            continue
        found += [(target, id(node) in top_level) for target in targets if target.startswith("drake_traj")]
    return found


GRAPH = {name: {target for target, _ in imports_of(name)} for name in MODULES}


def test_the_import_graph_has_no_cycle():
    state = {}  # 1: on the current path, 2: done

    def visit(name, path):
        state[name] = 1
        for target in sorted(GRAPH.get(name, ())):
            if state.get(target) == 1:
                cycle = path[path.index(target):] + [target]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if state.get(target) is None and target in GRAPH:
                visit(target, path + [target])
        state[name] = 2

    for name in sorted(GRAPH):
        if name not in state:
            visit(name, [name])


def test_every_import_of_the_package_is_at_module_level():
    late = [(name, target) for name in MODULES for target, top in imports_of(name) if not top]
    assert not late, f"function-level imports hide dependencies: {late}"


def test_dependencies_point_one_way():
    for name, targets in GRAPH.items():
        if name.startswith("drake_traj.robots"):
            assert not {t for t in targets if t.startswith(("drake_traj.planners", "drake_traj.station",
                                                            "drake_traj.scenario"))}, name
        if name.startswith("drake_traj.planners.baselines"):
            assert not {t for t in targets if t.startswith("drake_traj.planners.pajak")}, name
    assert "drake_traj.station" not in set().union(*(GRAPH[n] for n in MODULES if n.startswith("drake_traj.planners")))


@pytest.mark.parametrize("config", PLANNER_CONFIGS + (Scenario,), ids=lambda c: c.__name__)
def test_config_fields_have_real_types_for_yaml(config):
    # pydrake's yaml_load_typed reads dataclass field types; ``from __future__ import annotations``
    # in a config's module would turn them into strings it cannot use.
    for item in dataclasses.fields(config):
        assert not isinstance(item.type, str), f"{config.__name__}.{item.name}: {item.type!r}"


def test_public_api():
    for name in drake_traj.__all__:
        assert getattr(drake_traj, name) is not None
    for name in MODULES:  # each name exported once
        exported = getattr(importlib.import_module(name), "__all__", [])
        assert len(exported) == len(set(exported)), name
    assert issubclass(drake_traj.PlanningError, drake_traj.DrakeTrajError)
    assert issubclass(drake_traj.DrakeTrajError, ValueError)


def test_pure_laws_stand_apart_from_drake_systems():
    # planners.laws holds math only: no pydrake, and of the package only compiled, validation, errors and itself
    for name, path in MODULES.items():
        if not name.startswith("drake_traj.planners.laws"):
            continue
        tree = ast.parse(path.read_text())
        modules = {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
        modules |= {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module}
        assert not {m for m in modules if m.startswith("pydrake")}, name
        assert all(t.startswith(("drake_traj.planners.laws", "drake_traj.compiled", "drake_traj.validation",
                                  "drake_traj.errors"))
                   for t in GRAPH[name]), (name, GRAPH[name])


def test_the_pajak_law_reaches_the_robot_through_the_robot_interface():
    # its config describes the paper's task on the UR10e; the law, kernel, integration and system
    # use Robot.task_kinematics
    for name in MODULES:
        if name.startswith("drake_traj.planners.pajak") and name != "drake_traj.planners.pajak.parameters":
            assert "drake_traj.robots.ur10e" not in GRAPH[name], name


def test_every_package_of_the_source_tree_is_installed():
    """pyproject.toml lists the packages a non-editable install ships (as CI installs): a new
    subpackage missing from that list imports in a checkout but not after `pip install .`."""
    repository = Path(__file__).resolve().parents[1]
    listed = (repository / "pyproject.toml").read_text()
    for init in (repository / "drake_traj").rglob("__init__.py"):
        dotted = ".".join(init.parent.relative_to(repository).parts)
        assert f'"{dotted}"' in listed, f"{dotted} is not in pyproject.toml's [tool.setuptools] packages"
