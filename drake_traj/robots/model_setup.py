"""A description as published, read once and made to run: what it needed, applied to every plant.

:func:`read_model` parses a model file (:mod:`~drake_traj.robots.model_files`) into a plant of its
own and decides, once, what the description leaves open:

- the joints off the base-to-tool path held at a position (:mod:`~drake_traj.robots.locked_joints`);
- an inertia for the moving links without one (:mod:`~drake_traj.robots.inertia_estimate`);
- how the base is fixed to the world: the frame ``base_frame`` at the world's origin. A model
  that welds it there itself is used as it is; otherwise the root of the base's rigid assembly is
  welded at X_W_root = X_root_base⁻¹ (REP-199's ``base``, a fixed child of ``base_link`` turned by
  π about z on UR arms, then sits at the origin), replacing the model's own weld of its root to
  the world where that weld is at the origin.

The :class:`ModelSetup` holds those decisions; :meth:`ModelSetup.add_to` applies them to any plant
the arm is added to (the station's, the cell check's, a bench's), so each has the same model.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.multibody.tree import WeldJoint
from pydrake.systems.framework import DiagramBuilder

from drake_traj.robots.chain import plant_frame
from drake_traj.robots.inertia_estimate import DEFAULT_DENSITY, estimate_inertias, refuse_massless_assemblies
from drake_traj.robots.locked_joints import joints_to_lock, lock_joints
from drake_traj.robots.model_files import MODEL_FORMATS, add_model_file
from drake_traj.validation import invalid

__all__ = ["ModelSetup", "drake_reason", "read_model", "setup_note"]

WORLD_POSE_TOLERANCE = 1e-9  # [m, rad] a model's own weld of its base (or its root) to the world at the identity


@dataclass(frozen=True)
class ModelSetup:
    """What a model file needed to run as an arm, decided by :func:`read_model`.

    Attributes:
        locked_joints: {joint name: position [rad or m]} welded at that position.
        inertias: {link name: SpatialInertia M_BBo_B [kg, m, kg m²]} estimated from the link's
            shapes (written into the URDF text as its ``<inertial>``).
        density: the density of the estimates [kg/m³]; None where ``robot.inertia: refuse``.
        root_link: the body welded to the world at ``X_W_root``; None where the model's own weld
            puts the base frame at the world's origin (used as it is).
        X_W_root: that body's pose in the world.
        replaced_joint: the model's own joint welding ``root_link`` to the world (at the
            identity), replaced by the weld at ``X_W_root``; None where there is none.
    """

    locked_joints: dict = field(default_factory=dict)
    inertias: dict = field(default_factory=dict)
    density: float | None = None
    root_link: str | None = None
    X_W_root: RigidTransform = field(default_factory=RigidTransform)
    replaced_joint: str | None = None

    @property
    def estimated_masses(self) -> dict[str, float]:
        """{link name: estimated mass [kg]}, in the model's order."""
        return {link: float(inertia.get_mass()) for link, inertia in self.inertias.items()}

    def add_to(self, plant: MultibodyPlant, path: Path, packages: dict, xacro_args: dict):
        """Parse the model file ``path`` into ``plant`` (not finalized) with the estimated
        inertias, hold the locked joints, weld the base to the world; the model instance."""
        before = set(plant.GetConstraintIds())
        (instance,) = add_model_file(plant, path, packages, xacro_args=xacro_args, inertias=self.inertias)
        if self.locked_joints or self.replaced_joint:
            _drop_couplings(plant, before)
        lock_joints(plant, instance, self.locked_joints)
        if self.replaced_joint is not None:
            plant.RemoveJoint(plant.GetJointByName(self.replaced_joint, instance))
        if self.root_link is not None:
            plant.WeldFrames(plant.world_frame(), plant.GetBodyByName(self.root_link, instance).body_frame(), self.X_W_root)
        return instance


def read_model(path: Path, *, base_frame: str, tool_frame: str, packages: dict | None = None,
               xacro_args: dict | None = None, locked_joints: dict | None = None,
               density: float | None = DEFAULT_DENSITY) -> tuple[MultibodyPlant, ModelSetup]:
    """The finalized plant of the model file ``path`` alone (with SceneGraph: a ``package://`` URL
    that resolves nowhere is found here) and its :class:`ModelSetup`: the joints off the path from
    ``base_frame`` to ``tool_frame`` and those of ``locked_joints`` ({name: position}) held
    (welded in this plant too: its chain is the arm's), the moving links without inertia
    estimated at ``density`` [kg/m³] (None: refused), the base's weld to the world.

    Raises:
        DrakeTrajError: the file unreadable (at ``model_file``), a bad lock (``locked_joints``),
            links without inertia refused (``inertia``), a moving assembly of no mass
            (``model_file``), a base the model puts elsewhere than the origin (``base_frame``).
    """
    if not path.is_file():
        raise invalid("model_file", f"model file not found: {path}")
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    try:
        instances = add_model_file(plant, path, packages, xacro_args=xacro_args)
        instance = plant_frame(plant, base_frame, "base_frame").model_instance() if len(instances) > 1 else instances[0]
        positions = joints_to_lock(plant, instance, base_frame, tool_frame, dict(locked_joints or {}))
        if positions:
            _drop_couplings(plant, set())
        lock_joints(plant, instance, positions)
        plant.Finalize()
    except (RuntimeError, SystemExit) as error:  # Drake's parser exits on some bad data (a limit's lower > upper)
        raise invalid("model_file", f"the model file {path} could not be read: {drake_reason(error)}") from None
    # the estimates go into the URDF text: a file Drake's parser reads itself (SDF, whose links
    # without <inertial> weigh SDFormat's 1 kg) gets none, and a moving link of no mass is refused
    inertias = (estimate_inertias(plant, scene_graph.model_inspector(), instance, density)
                if path.suffix.lower() in MODEL_FORMATS else {})
    refuse_massless_assemblies(plant, instance, {link: inertia.get_mass() for link, inertia in inertias.items()})
    return plant, ModelSetup(positions, inertias, density, *_base_weld(plant, base_frame))


def _drop_couplings(plant: MultibodyPlant, before: set) -> None:
    """Remove the constraints added to ``plant`` since it had those of ``before``: the model's
    couplings (URDF ``<mimic>``). Drake removes a joint only from a plant without constraints, and
    a coupling of joints that are held holds nothing (a description's couplings are its gripper's)."""
    for constraint in [c for c in plant.GetConstraintIds() if c not in before]:
        plant.RemoveConstraint(constraint)


def setup_note(robot) -> str:
    """What a run says once, at its start, about what the arm's description needed (the held
    joints, the estimated inertias, as ``metrics.json``'s ``locked_joints`` and
    ``estimated_inertia_links``); empty for an arm that needed neither."""
    parts = []
    locked = getattr(robot, "locked_joints", {})
    if locked:
        parts.append("holds the joints it does not drive at " + ", ".join(f"{name} = {value:g}" for name, value in locked.items())
                     + " (locked_joints)")
    estimated = getattr(robot, "estimated_inertia", {})
    if estimated:
        masses = ", ".join(f"{link} {mass:.3g} kg" for link, mass in estimated.items())
        parts.append(f"estimates the inertia the description does not give from the links' shapes at "
                     f"{robot.inertia_density:g} kg/m^3: {masses} (estimated_inertia_links; torques rest on them)")
    return f"the {robot.name} model " + "; it ".join(parts) if parts else ""


def drake_reason(error: BaseException) -> str:
    """Drake's message of a parser failure (a SystemExit carries it as its code)."""
    return str(error.code if isinstance(error, SystemExit) else error).strip()


def _is_identity(pose: RigidTransform) -> bool:
    return max(float(np.abs(pose.translation()).max()),
               float(np.abs(pose.rotation().matrix() - np.eye(3)).max())) <= WORLD_POSE_TOLERANCE


def _base_weld(plant: MultibodyPlant, base_frame: str) -> tuple[str | None, RigidTransform, str | None]:
    """(root link, X_W_root, replaced joint) of :class:`ModelSetup` for the finalized ``plant``:
    the body at the top of the base frame's rigid assembly (up through fixed joints) and where to
    weld it so that ``base_frame`` is at the world's origin. DrakeTrajError at ``base_frame``
    where the model welds its root to the world elsewhere than the origin and the base is not
    there either, or where a joint that moves holds the base."""
    frame = plant_frame(plant, base_frame, "base_frame")
    by_child = {plant.get_joint(index).child_body().index(): plant.get_joint(index)
                for index in plant.GetJointIndices()}
    root = frame.body()
    while (isinstance(by_child.get(root.index()), WeldJoint)
           and by_child[root.index()].parent_body().index() != plant.world_body().index()):
        root = by_child[root.index()].parent_body()
    context = plant.CreateDefaultContext()
    X_root_base = plant.CalcRelativeTransform(context, root.body_frame(), frame)
    joint = by_child.get(root.index())
    if joint is None or joint.type_name().endswith("floating"):  # a free root (Finalize's floating joint)
        return root.name(), X_root_base.inverse(), None
    if not isinstance(joint, WeldJoint):  # (a joint above the base, off the chain, is held already)
        raise invalid("base_frame", f"base_frame {base_frame!r} hangs from the {joint.type_name()} joint "
                                    f"{joint.name()!r} beside the arm: an arm's base must be fixed")
    pose = frame.CalcPoseInWorld(context)
    if _is_identity(pose):
        return None, RigidTransform(), None  # the model's own weld, used as it is
    if _is_identity(plant.CalcRelativeTransform(context, plant.world_frame(), root.body_frame())):
        return root.name(), X_root_base.inverse(), joint.name()  # the model's root at the origin, the base beside it
    raise invalid("base_frame", f"the model welds base_frame {base_frame!r} to its world at "
                                f"xyz {np.round(pose.translation(), 6).tolist()} (and a rotation): poses and the "
                                "cell are given in the base frame at the world's origin; name the link the "
                                "model welds to the world at its origin as base_frame, or remove the offset")
