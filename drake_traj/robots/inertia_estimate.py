"""Inertia for the links a published description leaves without one, estimated from their shapes.

Most ROS-Industrial descriptions give their links no ``<inertial>``: Drake then takes them as
massless, and an arm whose moving links weigh nothing has no mass matrix to simulate with. A link
without inertia (no ``<inertial>``, or a mass of 0) that has shapes gets the inertia of a solid of
uniform density filling them: its collision shapes (its visual ones where it has none), a mesh as
its convex hull, each through Drake's ``CalcSpatialInertia(shape, density)`` moved into the link's
frame and summed. The density is :data:`DEFAULT_DENSITY` unless the scenario gives one
(``robot.inertia: {density: ...}``); ``robot.inertia: refuse`` refuses such links instead.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from pydrake.geometry import Convex, Mesh
from pydrake.multibody.tree import CalcSpatialInertia, SpatialInertia

from drake_traj.errors import Cause, DrakeTrajError

__all__ = ["DEFAULT_DENSITY", "DENSITY_RANGE", "estimate_inertias", "estimated_torque_note", "geometry_inertia",
           "inertial_element", "refuse_massless_assemblies"]

DEFAULT_DENSITY = 1370.0
"""[kg/m³] The default density of an estimated link: the median of mass / convex-hull volume over
the 123 distinct moving links of descriptions that publish their inertia (UR's ROS 2 description,
9 arms; Kinova's Gen3, 6 and 7 axes; Doosan's 8 arms; Techman's 8), 1369 kg/m³ (quartiles 874
and 2170, extremes 330 and 3587): a link's mass is within a factor of 1.6 of its estimate for
half of them, within 4.2 for all (docs/arm.md)."""

DENSITY_RANGE = (10.0, 30000.0)  # [kg/m³] a density given for an estimate: from foam to tungsten


def geometry_inertia(plant, inspector, body, density: float) -> SpatialInertia | None:
    """M_BBo_B: the spatial inertia about the body's origin Bo, in its frame B, of a solid of
    ``density`` [kg/m³] filling its collision shapes (its visual shapes where it has none), a
    mesh taken as its convex hull; None for a body without shapes. ``inspector``: the SceneGraph
    inspector the plant registered its geometry with."""
    geometries = plant.GetCollisionGeometriesForBody(body) or plant.GetVisualGeometriesForBody(body)
    if not geometries:
        return None
    total = SpatialInertia.Zero()
    for geometry in geometries:
        shape = inspector.GetShape(geometry)
        if isinstance(shape, Mesh):
            shape = Convex(shape.source(), shape.scale3())
        X_BG = inspector.GetPoseInFrame(geometry)
        total += CalcSpatialInertia(shape, density).ReExpress(X_BG.rotation()).Shift(-X_BG.translation())
    return total if total.get_mass() > 0.0 else None


def inertial_element(M_BBo_B: SpatialInertia) -> ElementTree.Element:
    """The URDF ``<inertial>`` of the spatial inertia M_BBo_B (about the link's origin, in its
    frame): its mass [kg], centre of mass [m] and the inertia about it [kg m²] in the link's axes."""
    com = M_BBo_B.get_com()
    central = M_BBo_B.Shift(com).CalcRotationalInertia().CopyToFullMatrix3()
    element = ElementTree.Element("inertial")
    ElementTree.SubElement(element, "origin", xyz=" ".join(repr(float(v)) for v in com), rpy="0 0 0")
    ElementTree.SubElement(element, "mass", value=repr(float(M_BBo_B.get_mass())))
    ElementTree.SubElement(element, "inertia", **{name: repr(float(central[i, k])) for name, (i, k) in (
        ("ixx", (0, 0)), ("iyy", (1, 1)), ("izz", (2, 2)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyz", (1, 2)))})
    return element


def _assemblies(plant, instance) -> list[list]:
    """The bodies each joint of ``instance`` with a degree of freedom moves (the joint's child and
    the bodies welded to it) in the finalized ``plant``; not a free root's own floating joint."""
    return [plant.GetBodiesWeldedTo(joint.child_body()) for joint in map(plant.get_joint, plant.GetJointIndices(instance))
            if joint.num_velocities() > 0 and not joint.type_name().endswith("floating")]


def estimate_inertias(plant, inspector, instance, density: float | None) -> dict[str, SpatialInertia]:
    """{link name: M_BBo_B} of the moving links of ``instance`` (finalized ``plant``) without
    inertia that have shapes (:func:`geometry_inertia` at ``density`` [kg/m³]). ``density`` None
    (``robot.inertia: refuse``): DrakeTrajError at ``inertia`` naming such links instead."""
    moving = {body.index(): body for bodies in _assemblies(plant, instance) for body in bodies}
    inertias = {}
    for body in sorted(moving.values(), key=lambda body: int(body.index())):
        if body.default_mass() > 0.0:
            continue
        estimate = geometry_inertia(plant, inspector, body, DEFAULT_DENSITY if density is None else density)
        if estimate is not None:
            inertias[body.name()] = estimate
    if density is None and inertias:
        raise DrakeTrajError(f"the links {', '.join(inertias)} move and have no inertia in the description (no "
                             "<inertial>, or a mass of 0), and inertia: refuse was asked: give them an <inertial>, or "
                             f"let them be estimated from their shapes (inertia: {{density: {DEFAULT_DENSITY:g}}}, kg/m^3)",
                             field=("inertia",), cause=Cause.INVALID)
    return inertias


def estimated_torque_note(estimated: dict, density) -> str:
    """What a message about joint torques adds when they rest on estimated inertia: ``estimated``
    ({link: mass [kg]}) at ``density`` [kg/m³]; empty where nothing was estimated."""
    if not estimated:
        return ""
    return (f" (the torques rest on inertia estimated from the shapes of the links {', '.join(estimated)} at "
            f"{density:g} kg/m^3: the description gives them none)")


def refuse_massless_assemblies(plant, instance, added: dict[str, float]) -> None:
    """DrakeTrajError (at ``model_file``) naming the links of the first assembly of ``instance``
    that a joint moves (the joint's child and the bodies welded to it) and that weighs nothing:
    neither the description nor an estimate (no shapes) gives it a mass (``added``: {link name:
    estimated mass [kg]}, not in the plant yet); a body of no mass behind a joint leaves the arm
    without a mass matrix."""
    for bodies in _assemblies(plant, instance):
        if not sum(body.default_mass() + added.get(body.name(), 0.0) for body in bodies) > 0.0:
            names = ", ".join(body.name() for body in bodies)
            raise DrakeTrajError(
                f"the model's link{'s' if len(bodies) > 1 else ''} {names} move{'' if len(bodies) > 1 else 's'} behind a "
                "joint and weigh nothing: the description gives no <inertial> and no shapes to estimate one from; give "
                "the link an <inertial> (mass, centre of mass, inertia) or a collision shape", field=("model_file",),
                cause=Cause.INVALID)
