"""Any 6-axis arm of revolute joints under the :class:`~drake_traj.robots.base.Robot` contract:
:class:`ChainArm`, a :class:`~drake_traj.robots.chain.SerialChain` (its compiled kinematics, the
numerical IK: :mod:`~drake_traj.robots.chain_kinematics`) with its model file, joint names, limits
and gains. A module of its own so that :mod:`drake_traj.robots.compiled_kinematics` (which imports
:mod:`~drake_traj.robots.chain_kinematics`) and this module import one way.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from drake_traj.errors import DrakeTrajError, joint_label
from drake_traj.robots.inertia_estimate import DEFAULT_DENSITY
from drake_traj.robots.model_files import add_model_file, joint_efforts
from drake_traj.robots.model_setup import ModelSetup, drake_reason, read_model
from drake_traj.robots import ROBOT_NAMES, arm_checks
from drake_traj.robots.base import Robot, TaskKinematics, format_point, joint_actuators
from drake_traj.robots.chain import SerialChain, plant_chain, plant_frame
from drake_traj.robots.chain_kinematics import (NUM_JOINTS, chain_reach, chain_singularity_factors,
                                                inverse_kinematics_all, inverse_kinematics_near)
from drake_traj.robots.compiled_kinematics import point_motion_rates, task_kinematics as arm_kinematics, task_kinematics_into
from drake_traj.robots.self_contact import srdf_file
from drake_traj.robots.task_space import orientation_error, pose_error, wrap_angle, wrapped
from drake_traj.robots.urdf_writer import dh_table_urdf
from drake_traj.validation import finite_array, invalid, joint_bound, joint_limit, path_argument

__all__ = ["ChainArm"]


# --------------------------------------------------------------------------------------------
# The Robot contract.
# --------------------------------------------------------------------------------------------

# Default PD gains: kp = KP_PER_EFFORT x the joint's effort limit, kd = KD_PER_KP x kp: the
# UR10e's shoulder (4000 N m/rad for 330 N m: a 1 rad error asks about 12 times the peak torque,
# and 200 N m s/rad); the inverse-dynamics feed-forward does most of the work.
KP_PER_EFFORT = 4000.0 / 330.0  # [1/rad]
KD_PER_KP = 0.05  # [s]
LIMIT_ARGUMENTS = ("lower_limits", "upper_limits", "velocity_limits", "acceleration_limits", "effort_limits",
                   "rated_payload", "home", "data_source", "unchecked_links", "srdf")  # the **limits of the constructors
FK_AGREEMENT = 1e-6  # [m and rad], a DH table and its model file must agree to this


class ChainArm(Robot):
    """A 6-axis arm of revolute joints under the :class:`~drake_traj.robots.base.Robot` contract:
    a :class:`SerialChain` (its compiled kinematics, ``model`` = :meth:`SerialChain.packed`) plus
    its data. Frames: the base frame ``base_frame`` (welded to the world), the flange
    ``tool_frame``, the TCP at :attr:`tcp_offset` in it (:meth:`with_tcp`). Build one with
    :meth:`from_model_file`, :meth:`from_plant` or :meth:`from_dh`.

    Args:
        chain: the kinematics.
        name: the arm's name (messages, scenario output).
        model_file: the URDF/SDF the simulation parses (:meth:`add_to_plant`); None for an arm
            only planned for (built from a user's plant) or one with ``model_text``.
        base_frame, tool_frame: frame names in the model file.
        joint_names: the six joints, base to tool.
        lower_limits, upper_limits: joint position limits [rad], (6,).
        velocity_limits, acceleration_limits: [rad/s], [rad/s²] (6,) or a scalar, > 0: the
            :attr:`joint_move_limits`.
        effort_limits: [N m] (6,) or a scalar, > 0.
        rated_payload: [kg] or None.
        home: the start configuration [rad] (6,); default zeros clipped into the limits (often a
            singular configuration, the arm stretched: give one for a task-space planner).
        data_source: where the numbers come from.
        model_text: the model as URDF text (an arm written from its DH table), parsed by
            :meth:`add_to_plant` instead of a file.
        packages: {package name: folder} for the model's ``package://`` URLs (with those of
            ``ROS_PACKAGE_PATH``: :mod:`drake_traj.robots.model_files`).
        xacro_args: a ``.xacro`` model's arguments.
        setup: what the model file needed to run (:class:`~drake_traj.robots.model_setup.ModelSetup`:
            joints held, inertia estimated, the base's weld to the world), applied by
            :meth:`add_to_plant`; None: the model used as it is, ``base_frame`` welded to the world.
        unchecked_links: links without collision shapes that may run unprotected, said
            explicitly (``("all",)``: every link); the cell check refuses an arm with such a link
            otherwise, and a run's metrics name them.
        srdf: the arm's MoveIt configuration (a ``.srdf`` file) whose ``<disable_collisions>``
            pairs the checks leave out (:mod:`~drake_traj.robots.self_contact`); None: none.

    Its :attr:`reach` is the chain's bound :func:`~drake_traj.robots.chain_kinematics.chain_reach` [m].
    """

    joint_types = ("revolute",) * NUM_JOINTS

    def __init__(self, chain: SerialChain, *, name: str, model_file, base_frame: str, tool_frame: str, joint_names,
                 lower_limits, upper_limits, velocity_limits, acceleration_limits, effort_limits,
                 rated_payload: float | None = None, home=None, data_source: str = "", model_text: str | None = None,
                 packages: dict | None = None, xacro_args: dict | None = None, setup: ModelSetup | None = None,
                 unchecked_links=(), srdf=None):
        if not isinstance(chain, SerialChain):
            raise TypeError(f"chain must be a SerialChain, got {type(chain).__name__}")
        arm_checks.arm_name(name, "name", plain=False)
        names = tuple(joint_names)
        if len(names) != NUM_JOINTS or not all(isinstance(n, str) and n for n in names):
            raise invalid("joint_names", f"joint_names must be six non-empty texts, got {names!r}")
        self.chain, self.name, self.joint_names = chain, name, names
        self.model_file = None if model_file is None else path_argument(model_file, "model_file").resolve()
        self.model_text = model_text
        self.packages = {str(k): Path(v) for k, v in (packages or {}).items()}
        self.xacro_args = dict(xacro_args or {})
        self.setup = setup
        self.base_welded = setup is not None and setup.root_link is None  # the model's own weld to the world, as it is
        self.locked_joints = dict(setup.locked_joints) if setup is not None else {}
        self.estimated_inertia = setup.estimated_masses if setup is not None else {}
        self.inertia_density = setup.density if setup is not None and setup.inertias else None
        self.unchecked_links = tuple(str(link) for link in unchecked_links)
        self.srdf = None if srdf is None else srdf_file(srdf)
        self.base_frame, self.tool_frame = str(base_frame), str(tool_frame)
        given = dict(lower_limits=lower_limits, upper_limits=upper_limits, velocity_limits=velocity_limits,
                     acceleration_limits=acceleration_limits, effort_limits=effort_limits)
        for key, value in given.items():
            if value is None:
                raise arm_checks.missing_limit(key, name)
        self._lower = joint_bound(lower_limits, "lower_limits", NUM_JOINTS, "rad")
        self._upper = joint_bound(upper_limits, "upper_limits", NUM_JOINTS, "rad")
        arm_checks.ranges(self._lower, self._upper, "lower_limits", "upper_limits")
        self._velocity = joint_limit(velocity_limits, "velocity_limits", NUM_JOINTS, "rad/s")
        self._acceleration = joint_limit(acceleration_limits, "acceleration_limits", NUM_JOINTS, "rad/s^2")
        self._effort = joint_limit(effort_limits, "effort_limits", NUM_JOINTS, "N m")
        self.rated_payload = arm_checks.payload(rated_payload, "rated_payload")
        home = np.clip(np.zeros(NUM_JOINTS), self._lower, self._upper) if home is None else \
            finite_array(home, "home", "rad", shape=(NUM_JOINTS,))
        if np.any((home < self._lower) | (home > self._upper)):
            j = int(np.argmax((home < self._lower) | (home > self._upper)))
            raise invalid("home", f"home {joint_label(j, names)} = {home[j]:.6g} rad is beyond its limits "
                                  f"[{self._lower[j]:.6g}, {self._upper[j]:.6g}] rad", j)
        self._home = home
        self.data_source = data_source or (f"the model file {self.model_file}" if self.model_file else
                                           "its DH table" if model_text else "a user's plant")
        self.model = chain.packed()
        self.reach = chain_reach(self.model)

    # ---- constructors ------------------------------------------------------------------------
    @classmethod
    def from_model_file(cls, path, *, base_frame: str, tool_frame: str, name: str | None = None,
                        packages: dict | None = None, xacro_args: dict | None = None, locked_joints: dict | None = None,
                        inertia_density: float | None = DEFAULT_DENSITY, **limits) -> "ChainArm":
        """The arm of a URDF/SDF file: the chain between ``base_frame`` and ``tool_frame`` read
        through MultibodyPlant (:meth:`SerialChain.from_plant`), the joint names and the
        position, velocity and effort limits from the file where it has them. ``limits`` (the
        keyword arguments of :class:`ChainArm`: lower_limits, upper_limits, velocity_limits,
        acceleration_limits, effort_limits, rated_payload, home, data_source) override the file;
        acceleration_limits must be given (URDF has none). ``packages`` ({name: folder}) and
        ``ROS_PACKAGE_PATH`` resolve ``package://`` URLs; a ``.xacro`` file is expanded with
        ``xacro_args`` (:mod:`drake_traj.robots.model_files`). What the description leaves open
        is decided once (:func:`~drake_traj.robots.model_setup.read_model`) and applied to every
        plant: the joints off the base-to-tool path and those of ``locked_joints`` ({name:
        position [rad or m]}) held; the moving links without inertia estimated from their shapes
        at ``inertia_density`` [kg/m³] (None: refused); ``base_frame`` at the world's origin (a
        model that welds it there itself is used as it is; REP-199's ``base`` below ``base_link``
        is put there by welding ``base_link``).

        Raises:
            DrakeTrajError: the file unreadable, the chain not six revolute joints, a limit
                neither in the file nor given, a bad lock, a link without inertia refused
                (naming the field).
        """
        path = path_argument(path, "model_file")
        name = _default_name(name, path.stem.removesuffix(".urdf"), f"the model file's name {path.name!r}")
        packages = {str(k): Path(v) for k, v in (packages or {}).items()}
        plant, setup = read_model(path, base_frame=base_frame, tool_frame=tool_frame, packages=packages,
                                  xacro_args=xacro_args, locked_joints=locked_joints, density=inertia_density)
        if limits.get("effort_limits") is None:  # the file's <limit effort> where it gives no actuators
            efforts = joint_efforts(path, packages, xacro_args=xacro_args)
            joints = plant_chain(plant, base_frame, tool_frame)[2]
            if efforts and all(np.isfinite(efforts.get(j.name(), np.inf)) and efforts.get(j.name(), 0) > 0 for j in joints):
                limits["effort_limits"] = np.array([efforts[j.name()] for j in joints])
        return cls.from_plant(plant, base_frame=base_frame, tool_frame=tool_frame, model_file=path,
                              name=name, packages=packages, xacro_args=xacro_args, setup=setup, **limits)

    @classmethod
    def from_plant(cls, plant: MultibodyPlant, *, base_frame, tool_frame, name: str | None = None, model_file=None,
                   chain: SerialChain | None = None, model_text: str | None = None, packages: dict | None = None,
                   xacro_args: dict | None = None, setup: ModelSetup | None = None, **limits) -> "ChainArm":
        """The arm of a finalized ``plant`` (a user's own, beside which a planner built from this
        arm runs): the chain from ``base_frame`` to ``tool_frame`` (Frames or names), the joint
        names, and the limits the plant has (position and velocity limits of the joints, effort
        limits of their actuators) unless ``limits`` gives them (see :meth:`from_model_file`).
        ``model_file``: the URDF/SDF of the arm for :meth:`add_to_plant` (None: the arm plans but
        cannot add itself to a station); ``model_text``: the arm's URDF text instead of a file;
        ``chain``: use this chain instead of the plant's (it
        must agree with the plant's to 1e-6 m and rad: :meth:`from_dh`); ``name`` defaults to
        the tool body's model instance name; ``setup``: what :meth:`add_to_plant` applies to the
        model file (:meth:`from_model_file`'s).
        """
        unknown = sorted(set(limits) - set(LIMIT_ARGUMENTS))
        if unknown:
            raise TypeError(f"unknown arguments {unknown}: the limits and data are {LIMIT_ARGUMENTS}")
        fixed, axes, joints = plant_chain(plant, base_frame, tool_frame)
        from_plant = SerialChain(fixed, axes)
        if chain is not None:
            _check_agreement(chain, from_plant)
        base, tool = plant_frame(plant, base_frame, "base_frame"), plant_frame(plant, tool_frame, "tool_frame")
        efforts = {plant.get_joint_actuator(index).joint().index(): plant.get_joint_actuator(index).effort_limit()
                   for index in plant.GetJointActuatorIndices()}
        found = dict(lower_limits=[j.position_lower_limits()[0] for j in joints],
                     upper_limits=[j.position_upper_limits()[0] for j in joints],
                     velocity_limits=[j.velocity_upper_limits()[0] for j in joints],
                     effort_limits=[efforts.get(j.index(), np.inf) for j in joints])
        name = _default_name(name, plant.GetModelInstanceName(tool.model_instance()), "the tool body's model instance")
        for key, values in found.items():
            if limits.get(key) is None:
                if not np.all(np.isfinite(values)):
                    raise arm_checks.missing_limit(key, name, arm_checks.unbounded_joints(values, [j.name() for j in joints]))
                limits[key] = np.array(values)
        return cls(chain or from_plant, name=name,
                   model_file=model_file, base_frame=base.name(), tool_frame=tool.name(),
                   joint_names=[j.name() for j in joints], model_text=model_text, packages=packages,
                   xacro_args=xacro_args, setup=setup, unchecked_links=limits.get("unchecked_links") or (),
                   **{key: limits.get(key) for key in LIMIT_ARGUMENTS if key != "unchecked_links"})

    @classmethod
    def from_dh(cls, name: str, table, convention: str = "standard", *, model_file=None, base_frame: str = "base",
                tool_frame: str = "tool0", masses=None, centres_of_mass=None, inertias=None, link_radius: float = 0.05,
                **limits) -> "ChainArm":
        """The arm of a DH table (:meth:`SerialChain.from_dh`; rows [d, a, alpha, theta_offset]
        in m and rad, ``convention`` "standard" or "modified").

        With ``model_file`` (URDF/SDF): simulated with that file, whose chain between
        ``base_frame`` and ``tool_frame`` must be the table's (checked to 1e-6 m and rad at a few
        configurations); joint names and limits as :meth:`from_model_file`.

        Without: the model is written from the table
        (:func:`~drake_traj.robots.urdf_writer.dh_table_urdf`: ``masses`` (6,) [kg],
        ``centres_of_mass`` (6, 3) [m] and ``inertias`` (6, 6) rows [Ixx, Iyy, Izz, Ixy, Ixz,
        Iyz] [kg m²] in the convention's DH frames i (None: at the frame origin; a ball of
        ``link_radius``), capsules of ``link_radius`` [m]) and kept as URDF text
        (:attr:`model_text`, its frames ``base`` and ``tool0``: ``base_frame`` and ``tool_frame``
        name a model file's); every limit (lower_limits, upper_limits, velocity_limits,
        acceleration_limits, effort_limits) must be given.

        Raises:
            DrakeTrajError: a missing limit or mass (naming it), a table and a model file that
                disagree, and the errors of the other constructors.
        """
        chain = SerialChain.from_dh(table, convention)
        arm_checks.dh_reach(np.asarray(table, dtype=float), "table")  # an absurd model before it is written
        if model_file is not None:
            path = path_argument(model_file, "model_file")
            plant, setup = read_model(path, base_frame=base_frame, tool_frame=tool_frame)
            return cls.from_plant(plant, base_frame=base_frame, tool_frame=tool_frame, name=name,
                                  model_file=path, chain=chain, setup=setup, **limits)
        arm_checks.arm_name(name, "name")  # (the written model's name)
        needed = dict(masses=masses, **{key: limits.get(key) for key in LIMIT_ARGUMENTS[:5]})
        for key, value in needed.items():
            if value is None:
                raise DrakeTrajError(f"{key} missing for the custom arm {name!r}: its model is written from the DH "
                                     f"table and needs it (pass {key}=)", field=(key,))
        # every argument checked before the model is written and parsed (Drake's parser exits the
        # process on some bad data, warns only on others)
        lower = joint_bound(limits["lower_limits"], "lower_limits", NUM_JOINTS, "rad")
        upper = joint_bound(limits["upper_limits"], "upper_limits", NUM_JOINTS, "rad")
        arm_checks.ranges(lower, upper, "lower_limits", "upper_limits")
        joint_limit(limits["acceleration_limits"], "acceleration_limits", NUM_JOINTS, "rad/s^2")
        arm_checks.payload(limits.get("rated_payload"), "rated_payload")
        text = dh_table_urdf(name, table, convention,
                             masses=arm_checks.joint_vector(masses, "masses", "kg", required=True, positive=True),
                             centres_of_mass=arm_checks.matrix(centres_of_mass, "centres_of_mass", "m", 3, required=False),
                             inertias=arm_checks.inertia_rows(inertias, "inertias"),
                             link_radius=arm_checks.link_radius(link_radius, "link_radius"), lower=lower, upper=upper,
                             velocity=joint_limit(limits["velocity_limits"], "velocity_limits", NUM_JOINTS, "rad/s"),
                             effort=joint_limit(limits["effort_limits"], "effort_limits", NUM_JOINTS, "N m"),
                             source=limits.get("data_source") or "")
        return cls.from_plant(_parsed_text(text), base_frame="base", tool_frame="tool0", name=name, chain=chain,
                              model_text=text, **limits)

    # ---- description -------------------------------------------------------------------------
    @property
    def lower_limits(self) -> np.ndarray:
        return self._lower.copy()

    @property
    def upper_limits(self) -> np.ndarray:
        return self._upper.copy()

    @property
    def velocity_limits(self) -> np.ndarray:
        return self._velocity.copy()

    @property
    def effort_limits(self) -> np.ndarray:
        return self._effort.copy()

    @property
    def joint_move_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """(velocity_limits [rad/s], acceleration_limits [rad/s²])."""
        return self._velocity.copy(), self._acceleration.copy()

    @property
    def default_gains(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """kp = :data:`KP_PER_EFFORT` x effort limit [N m/rad], kd = :data:`KD_PER_KP` x kp [N m s/rad]."""
        kp = KP_PER_EFFORT * self._effort
        return tuple(float(v) for v in kp), tuple(float(v) for v in KD_PER_KP * kp)

    @property
    def home_configuration(self) -> np.ndarray:
        return self._home.copy()

    # ---- model -------------------------------------------------------------------------------
    def model_path(self) -> Path:
        """The arm's model file (absolute); ValueError for an arm built without one (from a plant,
        or with its model as text: :meth:`add_to_plant` adds either)."""
        if self.model_file is None:
            raise invalid("model_file", f"the custom arm {self.name!r} was built from a plant without a model_file: "
                                        "give model_file= to add it to a simulation's plant")
        if not self.model_file.is_file():
            raise invalid("model_file", f"{self.name} model file not found: {self.model_file}")
        return self.model_file

    def add_to_plant(self, plant):
        """Parse the model (its URDF text, else its file with its :attr:`setup` applied: joints
        held, inertia estimated) into ``plant`` (not finalized), put ``base_frame`` at the world's
        origin, and give each of the six joints an actuator (the model's,
        whatever its name: :func:`~drake_traj.robots.base.joint_actuators`; ``{joint}_actuator``
        added where the model has none) with the arm's effort limit [N m]. Returns the model
        instance."""
        if self.model_text is not None:
            (instance,) = Parser(plant).AddModelsFromString(self.model_text, "urdf")
        elif self.setup is not None:
            instance = self.setup.add_to(plant, self.model_path(), self.packages, self.xacro_args)
        else:
            (instance,) = add_model_file(plant, self.model_path(), self.packages, xacro_args=self.xacro_args)
        if self.setup is None:  # (a model written from a DH table has none)
            plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(self.base_frame, instance))
        actuated = joint_actuators(plant, instance)
        for joint_name, effort in zip(self.joint_names, self._effort):
            actuator = actuated.get(joint_name)
            if actuator is None:
                actuator = plant.AddJointActuator(f"{joint_name}_actuator", plant.GetJointByName(joint_name, instance),
                                                  float(effort))
            actuator.set_effort_limit(float(effort))
            if actuator.effort_limit() != float(effort):
                raise RuntimeError(f"the effort limit of {actuator.name()} did not take effect")
        return instance

    # ---- kinematics --------------------------------------------------------------------------
    def _kinematics(self, q, qd):
        return arm_kinematics(self.model, q, qd, self.tcp_offset)

    def tcp_pose(self, q) -> np.ndarray:
        q = self.joint_positions(q)
        return self._kinematics(q, np.zeros_like(q))[0]

    def tool_position(self, q) -> np.ndarray:
        return self.tcp_pose(q)[..., :3]

    def tool_motion(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        _, jacobian, bias, _, _ = self._kinematics(q, qd)
        return (np.einsum("...ij,...j->...i", jacobian[..., :3, :], qd),
                np.einsum("...ij,...j->...i", jacobian[..., :3, :], qdd) + bias[..., :3])

    def inverse_kinematics_all(self, pose) -> np.ndarray:
        """Every joint solution (k, 6) [rad] of the TCP pose [x, y, z, φ_X, φ_Y, φ_Z] within the
        limits (:func:`inverse_kinematics_all`)."""
        return inverse_kinematics_all(self.model, pose, self.tcp_offset, self._lower, self._upper)

    def point_ik(self, points, reference) -> np.ndarray:
        """IK of TCP positions (N, 3) [m] at the TCP orientation of ``reference``, on its branch:
        each point's solution is Newton's from the previous point's (the first's from
        ``reference``: :func:`~drake_traj.robots.chain_kinematics.inverse_kinematics_near`, within 0.5 rad
        of it, regular, within the limits); where that fails, the solution of all
        (:meth:`inverse_kinematics_all`) nearest that start (each joint moved by whole turns
        towards it within the limits). Points along a path in order follow one branch."""
        reference = finite_array(reference, "reference", "rad", shape=(NUM_JOINTS,))
        orientation = self.tcp_pose(reference)[3:]
        out, start = [], reference
        for point in np.asarray(points, dtype=float).reshape(-1, 3):
            pose = np.concatenate([point, orientation])
            q = inverse_kinematics_near(self.model, pose, start, self.tcp_offset, self._lower, self._upper)
            if q is None:
                q = self._nearest_solution(pose, start)
            out.append(q)
            start = q
        return np.array(out).reshape(-1, NUM_JOINTS)

    def _nearest_solution(self, pose, start) -> np.ndarray:
        """The solution of ``pose`` (:meth:`inverse_kinematics_all`) nearest ``start`` [rad], each
        joint moved by whole turns towards it within the limits."""
        candidates = []
        for q in self.inverse_kinematics_all(pose):
            shifted = q + 2 * np.pi * np.round((start - q) / (2 * np.pi))
            candidates.append(np.where((shifted < self._lower) | (shifted > self._upper), q, shifted))
        return min(candidates, key=lambda q: float(np.sum((q - start) ** 2)))

    def joint_rates(self, q, v, a) -> tuple[np.ndarray, np.ndarray]:
        """qd = J⁻¹ [v; 0], qdd = J⁻¹ ([a; 0] - J̇q̇) with the TCP's analytic Jacobian: q (..., 6),
        v and a (..., 3) broadcast (:func:`~drake_traj.robots.compiled_kinematics.point_motion_rates`);
        :class:`~drake_traj.errors.SingularConfigurationError` at the Euler angles' gimbal lock."""
        return point_motion_rates(self.model, self.tcp_offset, q, v, a)

    def task_kinematics(self) -> TaskKinematics:
        """The compiled kinematics of the chain
        (:func:`~drake_traj.robots.chain_kinematics.chain_kinematics_into` through
        :func:`~drake_traj.robots.compiled_kinematics.task_kinematics_into`, ``model`` =
        :meth:`SerialChain.packed`), the numerical IK within the limits and the one-factor
        singularity factors, of the TCP ``tcp_offset``."""
        return TaskKinematics(task_kinematics_into, wrapped, orientation_error, wrap_angle, pose_error,
                              self.inverse_kinematics_all, self.tcp_offset,
                              functools.partial(chain_singularity_factors, self.model), self.model)


def _parsed_text(text: str) -> MultibodyPlant:
    """A finalized plant of the URDF ``text`` (written from a DH table) alone."""
    plant = MultibodyPlant(0.0)
    try:
        Parser(plant).AddModelsFromString(text, "urdf")
        plant.Finalize()
    except (RuntimeError, SystemExit) as error:
        raise invalid("table", f"the model written from the DH table could not be read: {drake_reason(error)}") from None
    return plant


def _default_name(name: str | None, default: str, origin: str) -> str:
    """``name``, or ``default`` (from ``origin``) unless that is a known robot's name (then a
    DrakeTrajError asking for ``name=``: a custom arm must not pass for a known robot)."""
    if name is not None:
        return name
    if default in ROBOT_NAMES:
        raise invalid("name", f"the custom arm's name would be {default!r} ({origin}), a known robot's name (runs and "
                              "exports are told apart by it): give the arm a name of its own (name=)")
    return default


def _check_agreement(chain: SerialChain, other: SerialChain) -> None:
    """DrakeTrajError unless the two chains' flange poses agree to :data:`FK_AGREEMENT` at a few
    configurations (zeros and three fixed pseudo-random ones)."""
    configurations = np.vstack([np.zeros(NUM_JOINTS), np.random.default_rng(0).uniform(-np.pi, np.pi, (3, 6))])
    mine = arm_kinematics(chain.packed(), configurations, np.zeros(NUM_JOINTS))[0]
    theirs = arm_kinematics(other.packed(), configurations, np.zeros(NUM_JOINTS))[0]
    gap = np.abs(mine - theirs)
    gap[:, 3:] = np.abs(wrap_angle(mine[:, 3:] - theirs[:, 3:]))
    if np.max(gap) > FK_AGREEMENT:
        k = int(np.argmax(np.max(gap, axis=1)))
        raise invalid("table", f"the DH table and the model file disagree: at q = {format_point(configurations[k])} rad "
                               f"the table puts the flange at {format_point(mine[k])} and the file at "
                               f"{format_point(theirs[k])} (m, rad)")
