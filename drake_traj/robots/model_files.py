"""Robot and cell description files as engineers have them: ``package://`` URLs, xacro, meshes.

- **Formats.** Each kind of description file is a :class:`ModelFormat` in :data:`MODEL_FORMATS`,
  keyed by its file name's ending: how the file becomes URDF text for the parser (a ``.urdf`` as
  it is, a ``.xacro`` expanded), or None where Drake's parser reads the file itself (SDF, and any
  ending not listed). A new format is one class here and its entry in :data:`MODEL_FORMATS`.

- **Packages.** A parser's package map holds the folders of ``ROS_PACKAGE_PATH`` (every package
  under them), then the packages a scenario names (``packages: {name: folder}``), which win. Drake
  also finds the package a model file itself sits in (its ``package.xml``). A ``package://`` URL
  of a package found nowhere is refused naming the package and how to give it; nothing is ever
  fetched.
- **Xacro.** A ``.xacro`` model is expanded with the ``xacro`` package (no ROS install): its
  ``$(find pkg)`` resolves through an ament index made for the packages of the map, its
  ``$(arg name)`` from the scenario's ``xacro_args``.
- **Meshes.** Meshes Drake does not read (STL, and COLLADA where ``pycollada`` is installed),
  collision and visual alike, are converted to OBJ with ``trimesh`` into a cache folder
  (``~/.cache/drake_traj/meshes``, or a temporary one; a COLLADA file's colours go into the OBJ's
  material file), and the URDF text names the OBJ. Relative mesh paths are made absolute (the
  text is parsed from a string). Drake checks a mesh collision shape as its convex hull.
- **Inertia.** Links given an estimated inertia (:mod:`drake_traj.robots.inertia_estimate`) get
  it as an ``<inertial>`` in the URDF text, so every plant the model is parsed into has it.
"""

from __future__ import annotations

import copy
import hashlib
import io
import os
import shutil
import tempfile
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import MultibodyPlant

from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.robots.inertia_estimate import inertial_element

__all__ = ["CONVERTED_MESH_TYPES", "MODEL_FORMATS", "ModelFormat", "add_model_file", "joint_efforts", "missing_package",
           "model_format", "model_parser", "model_text", "unknown_package"]

CONVERTED_MESH_TYPES = (".stl", ".dae")
"""Mesh files converted to OBJ before Drake reads them (it takes OBJ, VTK and glTF)."""

# Drake's parser reads its own tags by their prefix (drake:...): a rewritten text must keep it
ElementTree.register_namespace("drake", "http://drake.mit.edu")

# the packages every Drake parser knows (drake, and drake_models, fetched from the internet on
# first use: never looked up here); a given package of the same name is still used
_DRAKES_OWN = frozenset(PackageMap().GetPackageNames())


def model_parser(plant, packages: dict[str, Path] | None = None) -> Parser:
    """A Drake Parser for ``plant`` whose package map holds ``ROS_PACKAGE_PATH``'s packages and
    ``packages`` ({name: folder}, winning over the environment's)."""
    parser = Parser(plant)
    package_map = parser.package_map()
    if os.environ.get("ROS_PACKAGE_PATH"):
        package_map.PopulateFromRosPackagePath()
    for name, folder in (packages or {}).items():
        if package_map.Contains(name):
            package_map.Remove(name)
        package_map.Add(name, str(folder))
    return parser


def _add_own_package(parser: Parser, path: Path) -> None:
    """The package the model file sits in (the nearest ``package.xml`` above it), as Drake finds
    it for a file it parses itself (this text may be parsed from a string)."""
    for folder in Path(path).resolve().parents:
        manifest = folder / "package.xml"
        if manifest.is_file():
            try:
                parser.package_map().AddPackageXml(str(manifest))
            except RuntimeError:  # the map has a package of that name already (given, or on the path)
                pass
            return


def missing_package(text: str, parser: Parser, field: tuple, label: str) -> DrakeTrajError | None:
    """The clear error for the first ``package://`` URL in ``text`` whose package the parser's
    map does not hold (naming it and how to give it, at ``field``), else None. Checked before
    Drake parses the text, which would fail on it with its own words."""
    package_map = parser.package_map()
    start = 0
    while (found := text.find("package://", start)) >= 0:
        url = text[found:].split('"', 1)[0].split("'", 1)[0].split("<", 1)[0].strip()
        package = url[len("package://"):].split("/", 1)[0]
        start = found + len("package://")
        if package and not package_map.Contains(package):
            return unknown_package(package, url, field, label)
    return None


def unknown_package(package: str, reference: str, field: tuple, label: str) -> DrakeTrajError:
    """The refusal of a model's ``reference`` (a ``package://`` URL, a xacro ``$(find ...)``) to
    the package ``package`` that no package path here holds: its name and how to give it."""
    return DrakeTrajError(
        f"{label}: the model refers to the package {package!r} ({reference}), which is on no package path here: give "
        f"its folder in packages: {{{package}: path/to/{package}}} (relative to the scenario file) or put its "
        "parent folder on ROS_PACKAGE_PATH; nothing is downloaded", field=field, cause=Cause.INVALID)


def _resolve(url: str, base: Path, parser: Parser) -> Path | None:
    """The file of a mesh ``url`` (``package://``, ``file://``, absolute or relative to ``base``);
    None for a package the map does not know (the parser then says so)."""
    if url.startswith("package://"):
        package, _, rest = url[len("package://"):].partition("/")
        package_map = parser.package_map()
        if not package_map.Contains(package):
            return None
        return Path(package_map.GetPath(package)) / rest
    if url.startswith("file://"):
        return Path(url[len("file://"):])
    path = Path(url)
    return path if path.is_absolute() else base / path


def _cache_folder() -> Path:
    folder = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "drake_traj" / "meshes"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".write_test_"):  # a name of its own: processes share the folder
            pass
        return folder
    except OSError:
        return Path(tempfile.mkdtemp(prefix="drake_traj_meshes_"))


def _as_obj(path: Path, kind: str, field: tuple, label: str) -> Path:
    """``path`` (a ``kind`` mesh: STL or COLLADA) converted to OBJ in a folder of the cache named
    by its content, a COLLADA file's parts with their colours (an OBJ material file beside it).
    Written into a fresh folder and moved into place, so that runs in parallel never read half a file."""
    import trimesh  # a dependency of this conversion only
    from trimesh.exchange.obj import export_obj

    data = path.read_bytes()
    folder = _cache_folder() / f"{path.stem}-{hashlib.sha256(data).hexdigest()[:16]}"
    target = folder / f"{path.stem}.obj"
    if target.is_file():
        return target
    try:
        # a Scene of coloured parts (COLLADA) or one Trimesh (STL); text before a COLLADA file's XML
        # declaration (a blank line: some published files have one) is dropped, as ROS's loaders do
        content = data.lstrip() if path.suffix.lower() == ".dae" else data
        loaded = trimesh.load(io.BytesIO(content), file_type=path.suffix.lower()[1:])
        if path.suffix.lower() == ".dae":  # in the file's unit (<unit meter=...>), as ROS scales it; its
            loaded.apply_scale(_collada_metres(content))  # <up_axis> ignored, as ROS does
        text, materials = export_obj(loaded, include_texture=True, return_texture=True, mtl_name=f"{path.stem}.mtl")
    except Exception as error:  # noqa: BLE001 - trimesh raises many kinds; each is the same refusal
        hint = " (COLLADA needs the pycollada package: pip install pycollada)" if path.suffix.lower() == ".dae" else ""
        raise DrakeTrajError(f"{label}: the {kind} mesh {path} cannot be read{hint}: {error}", field=field,
                             cause=Cause.INVALID) from None
    if "\nv " not in text:
        raise DrakeTrajError(f"{label}: the {kind} mesh {path} has no vertices", field=field, cause=Cause.INVALID)
    staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}-", dir=folder.parent))
    (staging / target.name).write_text(text)
    for name, content in materials.items():
        (staging / name).write_bytes(content)
    try:
        staging.rename(folder)
    except OSError:  # another run put it there first
        shutil.rmtree(staging, ignore_errors=True)
    return target


def _collada_metres(content: bytes) -> float:
    """The length of a COLLADA file's unit in metres (its ``<asset><unit meter=...>``; 1 where
    it gives none)."""
    try:
        root = ElementTree.fromstring(content)
    except ElementTree.ParseError:
        return 1.0
    unit = next((element for element in root.iter() if element.tag.rsplit("}", 1)[-1] == "unit"), None)
    try:
        return float(unit.get("meter")) if unit is not None else 1.0
    except (TypeError, ValueError):
        return 1.0


class ModelFormat:
    """One kind of description file: how it reaches Drake's parser. The base reads a file Drake
    parses itself (``urdf_text`` None: the file is parsed as it is, no effort limits read from it)."""

    def urdf_text(self, path: Path, parser: Parser, arguments: dict, field: tuple, label: str) -> str | None:
        """The file ``path`` as URDF text (``arguments``: the scenario's ``xacro_args``), or None
        where the file is not URDF and Drake's parser reads it itself; errors at ``field``, ``label``."""
        return None

    def parse_as_is(self, text: str) -> bool:
        """Whether Drake can parse the file itself although it is URDF (``text``): nothing in it
        needs rewriting (no mesh to convert). A text made by :meth:`urdf_text` is parsed from a string."""
        return False


class UrdfFormat(ModelFormat):
    """A ``.urdf`` file: its own text; parsed as it is unless a mesh needs converting or a
    material needs its colour (:func:`_material_references`)."""

    def urdf_text(self, path, parser, arguments, field, label):
        return path.read_text()

    def parse_as_is(self, text):
        if any(kind in text.lower() for kind in CONVERTED_MESH_TYPES):
            return False
        try:
            return not _material_references(ElementTree.fromstring(text))
        except ElementTree.ParseError:
            return True  # Drake's parser says what is wrong, naming the file and line


class XacroFormat(ModelFormat):
    """A ``.xacro`` file, expanded with the ``xacro`` package (``$(find pkg)`` from the parser's
    package map, ``$(arg name)`` from ``arguments``)."""

    def urdf_text(self, path, parser, arguments, field, label):
        return _expand_xacro(path, parser, arguments, field, label)


MODEL_FORMATS: dict[str, ModelFormat] = {".urdf": UrdfFormat(), ".xacro": XacroFormat()}
"""Each description format by its file name's ending (lower case, with its dot); any other file
(``.sdf``, ``.xml``, ...) is read by Drake's parser as it is (:class:`ModelFormat`)."""


def model_format(path: Path) -> ModelFormat:
    """The :class:`ModelFormat` of the file ``path``, by its ending (Drake's own reading for one
    not in :data:`MODEL_FORMATS`)."""
    return MODEL_FORMATS.get(Path(path).suffix.lower(), ModelFormat())


def model_text(path: Path, parser: Parser, *, xacro_args: dict | None = None, inertias: dict | None = None,
               field: tuple = ("model_file",), label: str = "model_file") -> str | None:
    """The URDF text to parse for the model file ``path``: its format's text (:func:`model_format`:
    a ``.xacro`` expanded), relative mesh paths made absolute, STL/COLLADA meshes converted to OBJ
    and ``inertias`` ({link name: SpatialInertia M_BBo_B}) written as the links' ``<inertial>``;
    None where the file needs none of that (Drake parses it as it is)."""
    text = model_format(path).urdf_text(path, parser, xacro_args or {}, field, label)
    if text is None or (not inertias and model_format(path).parse_as_is(text)):
        return None
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise DrakeTrajError(f"{label}: {path} is not well-formed XML: {error}", field=field, cause=Cause.INVALID) from None
    for kind in ("collision", "visual"):
        for mesh in root.iter():
            if mesh.tag != kind:
                continue
            for element in mesh.iter("mesh"):
                url = element.get("filename", "")
                file = _resolve(url, path.parent, parser)
                if file is None:
                    continue  # an unknown package: the parser refuses it, naming it
                if not file.is_file():
                    raise DrakeTrajError(f"{label}: the {kind} mesh {url} ({file}) is not a file", field=field,
                                         cause=Cause.INVALID)
                if file.suffix.lower() in CONVERTED_MESH_TYPES:
                    element.set("filename", _as_obj(file, kind, field, label).resolve().as_uri())
                elif not url.startswith("package://"):  # a text parsed from a string takes file:// URLs only
                    element.set("filename", file.resolve().as_uri())
    _resolve_materials(root)
    for link in root.iter("link"):
        if link.get("name") in (inertias or {}):
            for old in link.findall("inertial"):
                link.remove(old)
            link.insert(0, inertial_element(inertias[link.get("name")]))
    return ElementTree.tostring(root, encoding="unicode")


def _colourless(material: ElementTree.Element) -> bool:
    return material.find("color") is None and material.find("texture") is None


def _material_references(root: ElementTree.Element) -> list:
    """The ``<material name=...>`` elements of the links' visuals that give no colour or texture
    of their own: ROS looks the name up among the robot's materials wherever they are defined,
    Drake only among those defined before (and refuses an unknown one)."""
    return [material for visual in root.iter("visual") for material in visual.findall("material")
            if _colourless(material)]


def _resolve_materials(root: ElementTree.Element) -> None:
    """Each visual's material reference (:func:`_material_references`) given the colour and
    texture of the robot's material of that name, as ROS reads it; a reference to a material
    the robot does not define is dropped (Drake's default colour, where ROS draws its own)."""
    defined = {material.get("name"): material for material in root.findall("material") if not _colourless(material)}
    for visual in root.iter("visual"):
        for material in visual.findall("material"):
            if not _colourless(material):
                continue
            if material.get("name") in defined:
                material.extend(copy.deepcopy(list(defined[material.get("name")])))
            else:
                visual.remove(material)


def _expand_xacro(path: Path, parser: Parser, arguments: dict, field: tuple, label: str) -> str:
    """The URDF text of the xacro file ``path`` with ``arguments`` ($(arg ...)); $(find pkg)
    from the parser's package map (an ament index made for it, as ROS 2 would have)."""
    import xacro  # the xacro package from the index: no ROS install

    package_map = parser.package_map()
    with tempfile.TemporaryDirectory(prefix="drake_traj_ament_") as prefix:
        index = Path(prefix) / "share" / "ament_index" / "resource_index" / "packages"
        index.mkdir(parents=True)
        links = {}  # the index's folder of each package -> the package's own folder
        for name in sorted(set(package_map.GetPackageNames()) - _DRAKES_OWN):
            (index / name).write_text("")
            link, folder = Path(prefix) / "share" / name, Path(package_map.GetPath(name)).resolve()
            link.symlink_to(folder)
            links[str(link)] = str(folder)
        previous = os.environ.get("AMENT_PREFIX_PATH")
        os.environ["AMENT_PREFIX_PATH"] = prefix + (os.pathsep + previous if previous else "")
        try:
            document = xacro.process_file(str(path), mappings={str(k): str(v) for k, v in arguments.items()})
        except Exception as error:  # noqa: BLE001 - xacro raises its own and Python's: each is this refusal
            missing = _missing_find(error)
            if missing is not None:
                raise unknown_package(missing, f"$(find {missing}) in {path.name} or a file it includes", field,
                                      label) from None
            raise DrakeTrajError(f"{label}: the xacro file {path} cannot be expanded: {type(error).__name__}: "
                                 f"{error}", field=field, cause=Cause.INVALID) from None
        finally:
            if previous is None:
                os.environ.pop("AMENT_PREFIX_PATH", None)
            else:
                os.environ["AMENT_PREFIX_PATH"] = previous
    text = document.toxml()
    for link, folder in links.items():  # $(find pkg) gave the index's temporary folder: the package's own
        text = text.replace(link, folder)
    return text


def _missing_find(error: Exception) -> str | None:
    """The package of a xacro ``$(find pkg)`` that failed because no package path holds it (ament's
    PackageNotFoundError, which xacro wraps in its own exception), else None."""
    seen = []
    while error is not None and error not in seen and type(error).__name__ != "PackageNotFoundError":
        seen.append(error)  # xacro nests its exceptions (an expression's inside an include's)
        error = getattr(error, "exc", None) or error.__cause__ or error.__context__
    if error is None or error in seen:
        return None
    text = str(error)
    return text.split("'")[1] if text.count("'") >= 2 else text.strip()


def joint_efforts(path: Path, packages: dict[str, Path] | None = None, *, xacro_args: dict | None = None) -> dict:
    """{joint name: effort limit [N m or N]} from a URDF's (or expanded xacro's) ``<limit effort>``
    tags: Drake keeps them only for joints with a ``<transmission>``, and ROS 2 descriptions
    declare their drives with ``ros2_control`` instead. Empty for a format that has no URDF text."""
    parser = model_parser(MultibodyPlant(0.0), packages)
    _add_own_package(parser, path)
    text = model_format(path).urdf_text(path, parser, xacro_args or {}, ("model_file",), "model_file")
    if text is None:
        return {}
    efforts = {}
    for joint in ElementTree.fromstring(text).iter("joint"):
        limit = joint.find("limit")
        if limit is not None and limit.get("effort") is not None:
            try:
                efforts[joint.get("name")] = float(limit.get("effort"))
            except ValueError:
                continue
    return efforts


def add_model_file(plant, path: Path, packages: dict[str, Path] | None = None, *, xacro_args: dict | None = None,
                   inertias: dict | None = None, field: tuple = ("model_file",), label: str = "model_file") -> list:
    """Parse the model file ``path`` (URDF, SDF, xacro) into ``plant`` with the package map of
    :func:`model_parser` (``inertias``: estimated ones to write into the links, :func:`model_text`);
    the model instances. Raises the clear refusal of an unknown package (:func:`missing_package`,
    checked before Drake parses) and lets the parser's other errors through."""
    parser = model_parser(plant, packages)
    _add_own_package(parser, path)
    text = model_text(path, parser, xacro_args=xacro_args, inertias=inertias, field=field, label=label)
    refusal = missing_package(path.read_text(errors="replace") if text is None else text, parser, field, label)
    if refusal is not None:
        raise refusal
    if text is None:
        return parser.AddModels(str(path))
    return parser.AddModelsFromString(text, "urdf")
