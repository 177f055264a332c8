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
- **Meshes.** Collision meshes that Drake cannot take as convex hulls (STL, and COLLADA where
  ``pycollada`` is installed) are converted to OBJ with ``trimesh`` into a cache folder
  (``~/.cache/drake_traj/meshes``, or a temporary one), and the URDF text names the OBJ; visual
  meshes are left as they are. Relative mesh paths are made absolute (the text is parsed from a
  string). Drake checks a mesh collision shape as its convex hull.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import MultibodyPlant

from drake_traj.errors import Cause, DrakeTrajError

__all__ = ["CONVERTED_MESH_TYPES", "MODEL_FORMATS", "ModelFormat", "add_model_file", "joint_efforts", "missing_package",
           "model_format", "model_parser", "model_text"]

CONVERTED_MESH_TYPES = (".stl", ".dae")
"""Collision mesh files converted to OBJ before Drake reads them (it takes OBJ, VTK and glTF)."""

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
            return DrakeTrajError(
                f"{label}: the model refers to the package {package!r} ({url}), which is on no package path here: give "
                f"its folder in packages: {{{package}: path/to/{package}}} (relative to the scenario file) or put its "
                "parent folder on ROS_PACKAGE_PATH; nothing is downloaded", field=field, cause=Cause.INVALID)
    return None


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
        probe = folder / ".write_test"
        probe.write_text("")
        probe.unlink()
        return folder
    except OSError:
        return Path(tempfile.mkdtemp(prefix="drake_traj_meshes_"))


def _as_obj(path: Path, field: tuple, label: str) -> Path:
    """``path`` (an STL or COLLADA mesh) converted to OBJ in the cache (named by its content)."""
    import trimesh  # a dependency of this conversion only

    data = path.read_bytes()
    target = _cache_folder() / f"{path.stem}-{hashlib.sha256(data).hexdigest()[:16]}.obj"
    if not target.is_file():
        try:
            mesh = trimesh.load(str(path), force="mesh")
        except Exception as error:  # noqa: BLE001 - trimesh raises many kinds; each is the same refusal
            hint = " (COLLADA needs the pycollada package: pip install pycollada)" if path.suffix.lower() == ".dae" else ""
            raise DrakeTrajError(f"{label}: the collision mesh {path} cannot be read{hint}: {error}", field=field,
                                 cause=Cause.INVALID) from None
        if not len(mesh.vertices):
            raise DrakeTrajError(f"{label}: the collision mesh {path} has no vertices", field=field, cause=Cause.INVALID)
        mesh.export(str(target))
    return target


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
    """A ``.urdf`` file: its own text; parsed as it is unless a collision mesh needs converting."""

    def urdf_text(self, path, parser, arguments, field, label):
        return path.read_text()

    def parse_as_is(self, text):
        return not any(kind in text.lower() for kind in CONVERTED_MESH_TYPES)


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


def model_text(path: Path, parser: Parser, *, xacro_args: dict | None = None, field: tuple = ("model_file",),
               label: str = "model_file") -> str | None:
    """The URDF text to parse for the model file ``path``: its format's text (:func:`model_format`:
    a ``.xacro`` expanded), relative mesh paths made absolute and STL/COLLADA collision meshes
    converted to OBJ; None where the file needs none of that (Drake parses it as it is)."""
    text = model_format(path).urdf_text(path, parser, xacro_args or {}, field, label)
    if text is None or model_format(path).parse_as_is(text):
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
                if kind == "collision" and file.suffix.lower() in CONVERTED_MESH_TYPES:
                    element.set("filename", _as_obj(file, field, label).resolve().as_uri())
                elif not url.startswith("package://"):  # a text parsed from a string takes file:// URLs only
                    element.set("filename", file.resolve().as_uri())
    return ElementTree.tostring(root, encoding="unicode")


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
            hint = ""
            if type(error).__name__ == "PackageNotFoundError":  # ament's, for a $(find pkg) of no package here
                name = str(error).strip("'\" ")
                hint = (f" (the package {name!r} is on no package path here: give its folder in packages: "
                        f"{{{name}: path/to/{name}}} or put its parent folder on ROS_PACKAGE_PATH)")
            raise DrakeTrajError(f"{label}: the xacro file {path} cannot be expanded: {type(error).__name__}: "
                                 f"{error}{hint}", field=field, cause=Cause.INVALID) from None
        finally:
            if previous is None:
                os.environ.pop("AMENT_PREFIX_PATH", None)
            else:
                os.environ["AMENT_PREFIX_PATH"] = previous
    text = document.toxml()
    for link, folder in links.items():  # $(find pkg) gave the index's temporary folder: the package's own
        text = text.replace(link, folder)
    return text


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
                   field: tuple = ("model_file",), label: str = "model_file") -> list:
    """Parse the model file ``path`` (URDF, SDF, xacro) into ``plant`` with the package map of
    :func:`model_parser`; the model instances. Raises the clear refusal of an unknown package
    (:func:`missing_package`, checked before Drake parses) and lets the parser's other errors through."""
    parser = model_parser(plant, packages)
    _add_own_package(parser, path)
    text = model_text(path, parser, xacro_args=xacro_args, field=field, label=label)
    refusal = missing_package(path.read_text(errors="replace") if text is None else text, parser, field, label)
    if refusal is not None:
        raise refusal
    if text is None:
        return parser.AddModels(str(path))
    return parser.AddModelsFromString(text, "urdf")
