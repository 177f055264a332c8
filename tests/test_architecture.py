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


# an installed package holds the shipped models/ and diagrams/ (pyproject's package-dir): data and
# example scripts, not code of the package's layers
SHIPPED_DATA = ("models", "diagrams")


def package_files(pattern: str) -> list[Path]:
    """The package's files matching ``pattern``, without the shipped data folders."""
    return [path for path in PACKAGE.rglob(pattern) if path.relative_to(PACKAGE).parts[0] not in SHIPPED_DATA]


MODULES = {module_name(path): path for path in package_files("*.py")}


def imports_of(name: str) -> list[tuple[str, bool]]:
    """(imported drake_traj module, imported at module level) for every import in ``name``,
    including those made through importlib: a string that is exactly a submodule's dotted name (the
    command line's ``importlib.import_module("drake_traj.cli.commands")``, the lazy table of
    ``drake_traj/__init__.py``) is an import made when the code runs."""
    tree = ast.parse(MODULES[name].read_text())
    top_level = {id(node) for node in tree.body}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            targets = [f"{node.module}.{alias.name}" if f"{node.module}.{alias.name}" in MODULES else node.module
                       for alias in node.names]
        elif isinstance(node, ast.Constant) and node.value in MODULES and "." in node.value and node.value != name:
            found.append((node.value, False))
            continue
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
    # the light command line loads its commands (and so Drake) only once a command is given, and
    # the package's top level imports its public names on first use (``import drake_traj`` stays light)
    lazy_by_design = {("drake_traj.cli.parser", "drake_traj.cli.commands")}
    late = [(name, target) for name in MODULES for target, top in imports_of(name)
            if not top and name != "drake_traj" and (name, target) not in lazy_by_design]
    assert not late, f"function-level imports hide dependencies: {late}"


# The layers, as docs/design.md draws them: each package of drake_traj and the packages it may import.
# "core" is the top-level modules (errors, validation, compiled, data, version); the package's own
# __init__ (the public API, imported lazily) stands above every layer.
LAYERS = {
    "core": set(),
    "robots": {"core"},
    "planners": {"robots", "core"},
    "cell": {"robots", "core"},
    "results": {"robots", "core"},
    "scenario": {"planners", "cell", "results", "robots", "core"},
    "station": {"scenario", "planners", "cell", "results", "robots", "core"},
    "bench": {"station", "scenario", "planners", "cell", "results", "robots", "core"},
    "cli": {"bench", "station", "scenario", "planners", "cell", "results", "robots", "core"},
}


def layer(name: str) -> str:
    parts = name.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in LAYERS else "core"


def test_every_folder_is_a_layer():
    folders = {path.name for path in PACKAGE.iterdir() if (path / "__init__.py").exists()} - set(SHIPPED_DATA)
    assert folders == set(LAYERS) - {"core"}, "a package of drake_traj missing from LAYERS, or a layer with no folder"


def test_dependencies_point_one_way():
    wrong = sorted((name, target) for name, targets in GRAPH.items() if name != "drake_traj"
                   for target in targets if layer(target) != layer(name) and layer(target) not in LAYERS[layer(name)])
    assert not wrong, f"imports against the layers (docs/design.md): {wrong}"
    core = [name for name in MODULES if layer(name) == "core" and name != "drake_traj"]
    assert not [(name, t) for name in core for t in GRAPH[name] if layer(t) != "core"]


def test_planner_packages_borrow_from_no_other_planner():
    # planners share the contract (planners.base), the pure laws and the shared timing, never one
    # another's modules; the one composition: the smooth package re-times Pająk 2024's planned path
    shared = ("drake_traj.planners.base", "drake_traj.planners.laws", "drake_traj.planners.timing")
    allowed = {("smooth", "pajak")}

    def planner_package(module: str) -> str | None:
        parts = module.split(".")
        if len(parts) < 3 or parts[1] != "planners" or module.startswith(shared) or module == "drake_traj.planners":
            return None
        return parts[2] if (PACKAGE / "planners" / parts[2]).is_dir() else None

    borrowed = sorted((name, target) for name, targets in GRAPH.items() for target in targets
                      if planner_package(name) and planner_package(target)
                      and planner_package(name) != planner_package(target)
                      and (planner_package(name), planner_package(target)) not in allowed)
    assert not borrowed, f"a planner package imports another one (move the shared part to {shared}): {borrowed}"


def _is_numba_kernel(function: ast.FunctionDef) -> bool:
    """A function compiled with numba (``@compiled``, ``@njit``), or a factory whose body is one."""
    return any(isinstance(node, ast.FunctionDef) and any(
        (decorator.id if isinstance(decorator, ast.Name) else getattr(decorator, "attr", "")) in ("compiled", "njit")
        for decorator in node.decorator_list) for node in ast.walk(function))


def test_house_limits_on_module_and_function_length():
    long_modules = {name: n for name, path in MODULES.items() if (n := len(path.read_text().splitlines())) > 600}
    assert not long_modules, f"modules over 600 lines: {long_modules}"
    long_functions = [f"{name}.{node.name} ({node.end_lineno - node.lineno + 1} lines)"
                      for name, path in MODULES.items() for node in ast.walk(ast.parse(path.read_text()))
                      if isinstance(node, ast.FunctionDef) and node.end_lineno - node.lineno + 1 > 80
                      and not _is_numba_kernel(node)]
    assert not long_functions, f"functions over 80 lines: {long_functions}"


def test_design_doc_lists_every_module_of_the_package():
    """docs/design.md's "Where each part lives" names every folder and module of drake_traj, and
    nothing that is not there: the picture matches the folders one to one."""
    design = (Path(__file__).resolve().parents[1] / "docs" / "design.md").read_text()
    tree = design.split("## Where each part lives", 1)[1].split("```", 2)[1]
    listed, folders = set(), []
    for line in tree.splitlines():
        token = line.split()[0] if line.strip() else ""
        if not token.endswith((".py", "/")):
            continue
        depth = (len(line) - len(line.lstrip())) // 4
        folders = folders[:depth]
        path = "/".join(folders + [token.rstrip("/")])
        if token.endswith("/"):
            folders.append(token.rstrip("/"))
        listed.add(path)
    actual = {path.relative_to(PACKAGE.parent).as_posix() for path in package_files("*.py")}
    actual |= {path.relative_to(PACKAGE.parent).as_posix() for path in package_files("*")
               if path.is_dir() and (path / "__init__.py").exists()}
    actual -= {path for path in actual if path.endswith(("__init__.py", "__main__.py"))}
    actual.add(PACKAGE.name)
    assert sorted(actual - listed) == [], "modules docs/design.md does not list"
    assert sorted(p for p in listed - actual if p.startswith("drake_traj")) == [], "listed in docs/design.md, not in drake_traj"


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
