"""The user's own models in the cell: ``cell.directives`` (Drake's ``ModelDirectives``), each
entry checked before Drake processes them so that an error names it (a model file missing or
unparsable, a ``package://`` URL no package resolves, a weld to an unknown frame, directives files
that include each other), and, once the plant is finalized, the refusal of bodies the station
cannot hold (a model welded to nothing, a model with joints that move).

Frames: a weld's and a frame's parents are scoped names (``model::frame``) of the plant's frames
(the world, the robot) or of the models added by earlier entries.
"""

from pathlib import Path

import yaml
from pydrake.multibody.parsing import ModelDirective, ModelDirectives, ProcessModelDirectives
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.systems.framework import DiagramBuilder

from drake_traj.errors import Cause, DrakeTrajError, Field, field_text
from drake_traj.robots.model_files import missing_package, model_parser

__all__ = ["refuse_free_bodies"]


def package_folders(packages: dict, directory: Path | None) -> dict[str, Path]:
    """``cell.packages`` as {name: folder}, relative folders from ``directory``; DrakeTrajError
    naming ``cell.packages.NAME`` for a folder that does not exist."""
    found = {}
    for name, folder in packages.items():
        path = Path(folder) if Path(folder).is_absolute() else Path(directory or ".") / folder
        if not isinstance(name, str) or not name or not path.is_dir():
            raise DrakeTrajError(f"cell.packages.{name}: {str(path)[:200]} is not a folder", field=("cell", "packages", name),
                                 cause=Cause.INVALID)
        found[name] = path
    return found


def _missing_package_of(url: str, parser, field: tuple, label: str) -> DrakeTrajError | None:
    """:func:`~drake_traj.robots.model_files.missing_package` of a directive's model file: its
    own URL's package, then the ``package://`` URLs inside the file."""
    refusal = missing_package(url, parser, field, label)
    if refusal is not None:
        return refusal
    if url.startswith("package://") or url.startswith("file://"):
        try:
            path = Path(parser.package_map().ResolveUrl(url)) if url.startswith("package://") else Path(url[len("file://"):])
            return missing_package(path.read_text(errors="replace"), parser, field, label) if path.is_file() else None
        except RuntimeError:
            return None
    return None


def add_directives(plant: MultibodyPlant, directives: list[ModelDirective], directory: Path | None,
                    packages: dict[str, Path] | None = None) -> dict:
    """Process Drake model directives in one call (Drake resolves a weld's frames among the
    models of the same call), each checked first so that an error names its entry of
    ``cell.directives``: a model file that is missing or cannot be parsed, a weld or frame
    naming a frame that is neither the plant's (the world, the robot) nor an earlier entry's.
    Returns {body scoped name: ``("cell", "directives", k)``} of the bodies the entries add."""
    base = Path(directory or ".").resolve()
    known = {}  # model instance name -> its frame names, for the models the entries add
    for index, directive in enumerate(directives):
        name = ("cell", "directives", index)
        if directive.add_model is not None:
            model = directive.add_model
            if "://" not in model.file:
                path = base / model.file
                if not path.is_file():  # False for a symbolic link that loops or leads nowhere
                    what = " (a symbolic link that loops or leads nowhere)" if path.is_symlink() else ""
                    raise DrakeTrajError(f"cell.directives[{index}].add_model.file: no model file {model.file!r} "
                                         f"(looked for {path}{what})", field=name + ("add_model", "file"),
                                         cause=Cause.INVALID)
                model.file = path.resolve().as_uri()
            scratch_builder = DiagramBuilder()  # with SceneGraph: its meshes' package:// URLs are resolved here
            scratch, _ = AddMultibodyPlantSceneGraph(scratch_builder, 0.0)
            parser = model_parser(scratch, packages)
            refusal = _missing_package_of(model.file, parser, name + ("add_model", "file"),
                                          f"cell.directives[{index}].add_model.file")
            if refusal is not None:
                raise refusal
            try:
                (instance,) = parser.AddModels(url=model.file)
            except (RuntimeError, ValueError) as error:
                raise DrakeTrajError(f"cell.directives[{index}].add_model: {model.file} cannot be used: "
                                     f"{str(error).strip()}", field=name + ("add_model", "file"), cause=Cause.INVALID) from None
            known[model.name] = {scratch.get_frame(frame).name() for frame in scratch.GetFrameIndices(instance)}
        for kind, frames in (("add_weld", ("parent", "child")), ("add_frame", ())):
            entry = getattr(directive, kind)
            if entry is None:
                continue
            names = [getattr(entry, frame) for frame in frames] if frames else [entry.X_PF.base_frame or "world"]
            for frame in names:
                if not _frame_known(plant, known, frame):
                    models = sorted(known) + ["world"]
                    raise DrakeTrajError(f"cell.directives[{index}].{kind}: unknown frame {frame!r} (scoped as "
                                         f"model::frame; models: {', '.join(models)} and the robot's)",
                                         field=name + (kind,), cause=Cause.INVALID)
            if kind == "add_frame":
                known.setdefault("", set()).add(entry.name)
        if directive.add_directives is not None:
            _refuse_include_cycle(directive.add_directives.file, name + ("add_directives", "file"), packages, base)
    try:
        added = ProcessModelDirectives(ModelDirectives(directives=directives), plant, model_parser(plant, packages))
    except (RuntimeError, ValueError) as error:
        raise DrakeTrajError(f"cell.directives: {str(error).strip()}", field=("cell", "directives"),
                             cause=Cause.INVALID) from None
    fields = {}
    for info in added:
        name = ("cell", "directives") + _directive_index(directives, info.model_name)
        for body in plant.GetBodyIndices(info.model_instance):
            fields[str(plant.get_body(body).scoped_name())] = name
    return fields


MAX_DIRECTIVES_DEPTH = 100  # add_directives files included in one another, at most this deep


def _directives_path(url: str, packages: dict[str, Path] | None, base: Path) -> Path | None:
    """The file of an ``add_directives`` URL (``file://``, ``package://`` through ``packages``
    and ``ROS_PACKAGE_PATH``, or a plain path from ``base``), None where it cannot be found
    (Drake then says why)."""
    try:
        if url.startswith("package://"):
            scratch = MultibodyPlant(0.0)
            return Path(model_parser(scratch, packages).package_map().ResolveUrl(url))
        path = Path(url[len("file://"):]) if url.startswith("file://") else Path(url)
        return path if path.is_absolute() else base / path
    except (RuntimeError, ValueError):
        return None


def _refuse_include_cycle(url: str, field: Field, packages: dict[str, Path] | None, base: Path) -> None:
    """Follow the ``add_directives`` includes from ``url`` (the files read here, before Drake
    reads them: Drake recurses without end on a cycle, until it crashes) and refuse a file that
    includes itself, directly or through others, naming the chain of files at ``field``; also a
    file that is a symbolic link loop, and includes nested deeper than
    :data:`MAX_DIRECTIVES_DEPTH`. A file that cannot be read or is not a directives file is left
    to Drake's own message."""
    label = field_text(field)

    def follow(url: str, chain: list[str], seen: list[Path]) -> None:
        path = _directives_path(url, packages, base)
        if path is None:
            return
        if path.is_symlink() and not path.is_file():
            raise DrakeTrajError(f"{label}: the directives file {url!r} is a symbolic link that loops or leads nowhere "
                                 f"({path})", field=field, cause=Cause.INVALID)
        try:
            real = path.resolve(strict=True)
            text = real.read_text(errors="replace")
        except (OSError, RuntimeError):
            return
        chain = chain + [url]
        if real in seen:
            raise DrakeTrajError(f"{label}: the directives files include each other in a cycle: "
                                 f"{' -> '.join(chain)} (a file must not include itself, directly or through others)",
                                 field=field, cause=Cause.INVALID)
        if len(chain) > MAX_DIRECTIVES_DEPTH:
            raise DrakeTrajError(f"{label}: the directives files are included more than {MAX_DIRECTIVES_DEPTH} deep "
                                 f"({' -> '.join(chain[:3])} -> ...)", field=field, cause=Cause.INVALID)
        if real in done:  # its includes were followed already, without a cycle
            return
        try:
            document = yaml.safe_load(text)
        except yaml.YAMLError:
            return
        entries = document.get("directives") if isinstance(document, dict) else None
        for entry in entries if isinstance(entries, list) else []:
            nested = entry.get("add_directives") if isinstance(entry, dict) else None
            if isinstance(nested, dict) and isinstance(nested.get("file"), str):
                follow(nested["file"], chain, seen + [real])
        done.add(real)

    done = set()
    follow(url, [], [])


def _directive_index(directives: list[ModelDirective], model: str) -> tuple:
    """``(k,)`` of the entry of ``directives`` that adds the model instance ``model`` (its
    ``add_model``, or the ``add_directives`` whose namespace it is in); () if none is known."""
    for index, directive in enumerate(directives):
        if directive.add_model is not None and directive.add_model.name == model:
            return (index,)
        if directive.add_model_instance is not None and directive.add_model_instance.name == model:
            return (index,)
        nested = directive.add_directives
        if nested is not None and nested.model_namespace and model.startswith(f"{nested.model_namespace}::"):
            return (index,)
    return ()


def refuse_free_bodies(plant: MultibodyPlant, robot_instance, fields: dict | None = None) -> None:
    """Refuse a body of the finalized ``plant`` that is not the robot's (model instance
    ``robot_instance``) and is joined to nothing: a floating base body, which the simulation
    lets fall and the cell check would take for an obstacle at its model's default pose. A
    model of ``cell.directives`` (its bodies in ``fields``,
    :func:`~drake_traj.cell.cell.add_cell`'s return) is named by its entry (``field``
    ``("cell", "directives", k)``; the remedy an ``add_weld``), any other (a station's
    ``before_finalize`` bodies) by its model (the remedy a weld before the plant is finalized). DrakeTrajError, cause INVALID; the first such body in index order.

    Then a model other than the robot's with joints that move (a second arm welded beside the
    robot): the station drives and feeds forward the robot's joints only (its controller sees
    the robot's state, not the plant's), nothing would drive those joints, and the cell check
    would take the model for an obstacle at its default pose. Refused naming the model and its
    joints, at its directive where it has one."""
    fields = fields or {}
    _refuse_floating(plant, robot_instance, fields)
    moving = {}  # model instance -> its joints with a degree of freedom, in index order
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        if joint.model_instance() != robot_instance and joint.num_velocities() > 0:
            moving.setdefault(joint.model_instance(), []).append(joint)
    for instance, joints in sorted(moving.items(), key=lambda item: int(item[0])):
        model = plant.GetModelInstanceName(instance)
        names = ", ".join(repr(joint.name()) for joint in joints)
        what = (f"model {model!r} has joints that move ({names}): the station drives the robot's joints only, nothing "
                "would hold these, and the cell check would take the model for an obstacle at its default pose")
        field = next((fields[str(plant.get_body(body).scoped_name())] for body in plant.GetBodyIndices(instance)
                      if str(plant.get_body(body).scoped_name()) in fields), None)
        if field is not None and field[:2] == ("cell", "directives"):
            raise DrakeTrajError(f"{field_text(field)}: {what}: give a model whose joints are fixed (URDF type "
                                 "\"fixed\") for a second arm that stands still", field=field, cause=Cause.INVALID)
        raise DrakeTrajError(f"{what}: add it with fixed joints (URDF type \"fixed\", or weld its bodies) before the "
                             "plant is finalized", cause=Cause.INVALID)


def _refuse_floating(plant: MultibodyPlant, robot_instance, fields: dict) -> None:
    """:func:`refuse_free_bodies`' floating base bodies."""
    for index in sorted(plant.GetFloatingBaseBodies(), key=int):
        body = plant.get_body(index)
        if body.model_instance() == robot_instance:
            continue
        model, scoped = plant.GetModelInstanceName(body.model_instance()), str(body.scoped_name())
        what = f"model {model!r} is not welded to anything (its body {body.name()!r} would fall freely)"
        field = fields.get(scoped)
        if field is not None and field[:2] == ("cell", "directives"):
            raise DrakeTrajError(f"{field_text(field)}: {what}: add an add_weld {{parent: world, child: {scoped}}} "
                                 "after it (X_PC: where it stands), or weld it to another model's frame",
                                 field=field, cause=Cause.INVALID)
        raise DrakeTrajError(f"{what}: weld it before the plant is finalized (in before_finalize: "
                             f"plant.WeldFrames(plant.world_frame(), plant.GetBodyByName({body.name()!r}, "
                             f"plant.GetModelInstanceByName({model!r})).body_frame(), X_WB))",
                             cause=Cause.INVALID)


def _frame_known(plant: MultibodyPlant, known: dict, frame: str) -> bool:
    """Whether ``frame`` (``model::frame`` or a plain name) is the world, a frame of the plant
    or of a model in ``known`` ({instance name: frame names})."""
    if frame == "world":
        return True
    model, _, element = frame.rpartition("::")
    if model in known:
        return element in known[model]
    if model and plant.HasModelInstanceNamed(model):
        return plant.HasFrameNamed(element, plant.GetModelInstanceByName(model))
    return not model and (element in known.get("", set()) or plant.HasFrameNamed(element))
