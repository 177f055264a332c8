"""Advancing a simulator over a station (:mod:`drake_traj.station.loop`) until its planner has
finished: the motion checked before it starts, watched while it runs, and contact reported by the
plant turned into a failed run (:func:`run_station`, :func:`contact_failure`); Ctrl-C stops it
with what it logged, and goes on up to the caller."""

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import Diagram

from drake_traj.cell.clearance import geometry_owner
from drake_traj.errors import Cause, Failure, interrupt_in, reraise_interrupt
from drake_traj.validation import callable_or_none, instance_of, invalid, run_duration, settle_duration

__all__ = ["run_station"]


def run_station(simulator: Simulator, station: Diagram, *, settle_time: float = 0.5,
                max_duration: float = 120.0, progress=None) -> Failure | None:
    """Advance ``simulator`` (over ``station``, possibly inside a larger diagram) until the
    planner has finished plus ``settle_time`` [s], or ``max_duration`` [s].

    The motion starts only where the planner's plan was accepted by the cell check in the
    station's own scene; where it was not, it is checked first, and a refusal is raised (a
    :class:`~drake_traj.errors.PlanningError`, e.g. a
    :class:`~drake_traj.cell.clearance.CollisionError`) before anything moves, unless the station was
    built with ``check_motion=False`` (:mod:`drake_traj.cell.guard`). While it runs, the measured
    motion is watched (:class:`~drake_traj.cell.guard.ClearanceWatch`): closer than half the clearance
    to anything, between logged samples included, it fails the run naming the bodies and the
    time (cause "collision"), as contact reported by the plant does.

    Any exception from the simulation is caught: the state and logs stay as they were when it
    happened, and the :class:`Failure` is returned. Ctrl-C (KeyboardInterrupt) stops the run the
    same way, and the KeyboardInterrupt goes on to the caller (whose script stops, as on any
    Ctrl-C, unless it catches it) with a ``failure`` attribute: the :class:`Failure` (cause
    "interrupted", the simulated time); the station's loggers hold the log up to it
    (``SimulationResult.from_station(station, context, failure=stop.failure)``).
    ``progress(t)`` is called with the simulated time every 10 ms of it. Returns None when the
    planner finished, else the :class:`Failure`.

    TypeError unless ``simulator`` is a ``Simulator`` and ``station`` a station Diagram in its
    diagram; ValueError for a ``max_duration`` outside (0, 600] s or a ``settle_time`` outside
    [0, 60] s (:data:`~drake_traj.validation.MAX_RUN_DURATION`, ``MAX_SETTLE_TIME``).
    """
    instance_of(simulator, Simulator, "simulator")
    instance_of(station, Diagram, "station", hint=" (make_station(scenario) or build_station(planner))")
    max_duration = run_duration(max_duration)
    settle_time = settle_duration(settle_time)
    callable_or_none(progress, "progress", "progress(t)")
    if not station.HasSubsystemNamed("planner"):
        raise invalid("station", f"station must be a station (make_station, build_station): {station.get_name()!r} has no "
                                 "subsystem named 'planner'")
    planner = station.GetSubsystemByName("planner")
    root = simulator.get_mutable_context()
    try:
        planner_context = planner.GetMyContextFromRoot(root)
    except RuntimeError:
        raise invalid("station", f"station {station.get_name()!r} is not part of the simulator's diagram "
                                 f"({simulator.get_system().get_name()!r})") from None
    guard = planner.guard
    watch = None
    if guard is not None:
        try:
            guard.ensure_checked(planner, max_duration)  # a refusal raised before the motion
        except Exception as error:
            reraise_interrupt(error)  # a Ctrl-C during the check (e.g. Pająk's compiled integration) stops as one
            raise
        watch = guard.watch(station.GetSubsystemByName("measured_logger"), root, planner.num_joints)
    chunk = min(0.01, max(settle_time, 1e-3))  # the finish and contact are checked between chunks
    end = max_duration
    try:
        while root.get_time() < end:
            simulator.AdvanceTo(min(root.get_time() + chunk, end))
            if progress is not None:
                progress(root.get_time())
            touching = (watch.feed() if watch is not None else None) or contact_failure(station, root)
            if touching is not None:
                return touching
            finish = planner.finish_time(planner_context)
            if np.isfinite(finish) and end == max_duration:
                end = min(max(finish + settle_time, root.get_time()), max_duration)
        if np.isfinite(planner.finish_time(planner_context)):
            return None
        return Failure(Cause.TIMEOUT, f"planner did not finish within max_duration = {max_duration} s", root.get_time(),
                       tuple(planner.reference_state(planner_context)[: planner.num_joints].tolist()))
    except (KeyboardInterrupt, Exception) as error:  # keep the log up to the failure; the reason goes in the result
        stop = interrupt_in(error)
        if stop is None:
            return Failure.from_exception(error, root.get_time())
        # Ctrl-C or SIGTERM (even one that came as compiled code returned): the caller stops too,
        # told where the run stopped
        stop.failure = Failure(Cause.INTERRUPTED, f"interrupted at t = {root.get_time():.4f} s", root.get_time())
        raise stop from None


def contact_failure(station: Diagram, root_context) -> Failure | None:
    """A COLLISION :class:`Failure` when the station's plant reports contact (the arm with
    itself, its tool or its cell) in ``root_context``, naming the two bodies, the depth and the
    time; None without contact. Read from the plant's contact results (point pairs and
    hydroelastic surfaces), so a touch shorter than a check's interval may pass unseen."""
    plant = station.GetSubsystemByName("plant")
    plant_context = plant.GetMyContextFromRoot(root_context)
    results = plant.get_contact_results_output_port().Eval(plant_context)
    pairs = [(info.point_pair().id_A, info.point_pair().id_B, -info.point_pair().depth)
             for info in map(results.point_pair_contact_info, range(results.num_point_pair_contacts()))]
    pairs += [(info.contact_surface().id_M(), info.contact_surface().id_N(), float("nan"))
              for info in map(results.hydroelastic_contact_info, range(results.num_hydroelastic_contacts()))]
    if not pairs:
        return None
    inspector = station.GetSubsystemByName("scene_graph").model_inspector()
    robot_instance = plant.get_joint_actuator(plant.GetJointActuatorIndices()[0]).model_instance()  # the robot's drives
    id_a, id_b, distance = min(pairs, key=lambda pair: pair[2] if np.isfinite(pair[2]) else 0.0)
    (body_a, _), (body_b, _) = (geometry_owner(plant, inspector, geometry, robot_instance) for geometry in (id_a, id_b))
    t = root_context.get_time()
    depth = f", {-distance * 1000:.1f} mm deep" if np.isfinite(distance) else ""
    q = plant.GetPositions(plant_context, robot_instance)
    return Failure(Cause.COLLISION, f"collision between {body_a} and {body_b} at t = {t:.3f} s{depth}", t,
                   tuple(q.tolist()))
