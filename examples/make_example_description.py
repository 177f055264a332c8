"""Write models/example_arm_description/: an arm description laid out as engineers get one from
a ROS package, made by us for the tests (docs/arm.md).

The arm is our UR5e model (models/ur5e.urdf, written from UR's published data) with every
collision and visual shape replaced by a mesh file of its own: cylinders as 32-sided prisms and
capsules as trimesh's capsule meshes,
written as OBJ for the base, shoulder, upper arm and forearm and as binary STL for the wrists
(STL collision meshes are converted to OBJ when the model is read: drake_traj.robots.model_files), all
named by ``package://example_arm_description/meshes/...`` URLs, and the base fixed to a ``world``
link by the file itself. Run from the repository's top folder:

    python examples/make_example_description.py
"""

from __future__ import annotations

import struct
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "models" / "ur5e.urdf"
PACKAGE = "example_arm_description"
SIDES = 32
STL_LINKS = ("wrist_1_link", "wrist_2_link", "wrist_3_link")


def prism(radius: float, length: float) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """A cylinder's 32-sided prism about z, centred: vertices (2 x 32 + 2, 3), triangles."""
    angles = np.arange(SIDES) * 2 * np.pi / SIDES
    ring = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    vertices = np.vstack([np.column_stack([ring, np.full(SIDES, -length / 2)]),
                          np.column_stack([ring, np.full(SIDES, length / 2)]),
                          [[0, 0, -length / 2], [0, 0, length / 2]]])
    bottom, top = 2 * SIDES, 2 * SIDES + 1
    faces = []
    for k in range(SIDES):
        n = (k + 1) % SIDES
        faces += [(k, n, SIDES + n), (k, SIDES + n, SIDES + k), (bottom, n, k), (top, SIDES + k, SIDES + n)]
    return vertices, faces


def capsule(radius: float, length: float) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """A capsule about z (cylinder ``length`` between the caps' centres), centred, as a mesh."""
    import trimesh

    mesh = trimesh.creation.capsule(height=length, radius=radius, count=[SIDES, SIDES])
    vertices = np.asarray(mesh.vertices) - 0.5 * (mesh.bounds[0] + mesh.bounds[1])
    return vertices, [tuple(int(i) for i in face) for face in mesh.faces]


def write_obj(path: Path, vertices, faces) -> None:
    lines = ["# drake_traj example arm: a cylinder as a 32-sided prism [m]"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def write_stl(path: Path, vertices, faces) -> None:
    with path.open("wb") as stream:
        stream.write(b"drake_traj example arm: a cylinder as a 32-sided prism [m]".ljust(80, b" "))
        stream.write(struct.pack("<I", len(faces)))
        for face in faces:
            a, b, c = (vertices[i] for i in face)
            normal = np.cross(b - a, c - a)
            normal = normal / (np.linalg.norm(normal) or 1.0)
            stream.write(struct.pack("<12fH", *normal, *a, *b, *c, 0))


def main() -> Path:
    folder = ROOT / "models" / PACKAGE
    (folder / "urdf").mkdir(parents=True, exist_ok=True)
    (folder / "meshes").mkdir(exist_ok=True)
    (folder / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3">\n  <name>example_arm_description</name>\n'
        "  <version>0.1.0</version>\n  <description>drake_traj's example arm description in a ROS package's "
        "layout: meshes, package:// URLs, a world link (examples/make_example_description.py)</description>\n"
        '  <maintainer email="drake-traj@example.org">drake_traj</maintainer>\n  <license>BSD-3-Clause</license>\n'
        "</package>\n")
    ElementTree.register_namespace("drake", "http://drake.mit.edu")  # Drake reads its tags by their prefix
    tree = ElementTree.parse(SOURCE)
    robot = tree.getroot()
    robot.set("name", "example_arm")
    for link in robot.findall("link"):
        for kind in ("collision", "visual"):
            for element in link.findall(kind):
                geometry = element.find("geometry")
                shape = geometry.find("cylinder")
                if shape is None:
                    shape = geometry.find("{http://drake.mit.edu}capsule")
                if shape is None:
                    continue
                name = element.get("name") or f"{link.get('name')}_{kind}"
                suffix = ".stl" if link.get("name") in STL_LINKS and kind == "collision" else ".obj"
                maker = prism if shape.tag == "cylinder" else capsule
                vertices, faces = maker(float(shape.get("radius")), float(shape.get("length")))
                file = folder / "meshes" / f"{name}{suffix}"
                (write_stl if suffix == ".stl" else write_obj)(file, vertices, faces)
                geometry.remove(shape)
                ElementTree.SubElement(geometry, "mesh", filename=f"package://{PACKAGE}/meshes/{name}{suffix}")
    world = ElementTree.Element("link", name="world")
    weld = ElementTree.Element("joint", name="world_joint", type="fixed")
    ElementTree.SubElement(weld, "parent", link="world")
    ElementTree.SubElement(weld, "child", link="base")
    ElementTree.SubElement(weld, "origin", xyz="0 0 0", rpy="0 0 0")
    robot.insert(0, weld)
    robot.insert(0, world)
    ElementTree.indent(tree)
    out = folder / "urdf" / "example_arm.urdf"
    out.write_text("<?xml version=\"1.0\"?>\n<!-- Written by examples/make_example_description.py from models/ur5e.urdf: "
                   "every shape a mesh of this package, the base fixed to a world link. -->\n"
                   + ElementTree.tostring(robot, encoding="unicode") + "\n")
    print(f"wrote {folder}")
    return folder


if __name__ == "__main__":
    main()
