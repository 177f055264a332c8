"""Replay a run's reference in another Drake diagram: the reference as a PiecewisePolynomial
(``SimulationResult.reference_trajectory()``) driving a ``TrajectorySource``.

    python examples/replay_reference.py [RUN_DIR]

RUN_DIR defaults to the main job's folder: ``out`` (the README's ``drake-traj run --out out``) or
``out/pajak_sim3`` (``drake-traj run``'s own default), the first that holds a run.

The diagram here is a bare UR10e plant with its PD actuators and gravity compensation (no
feed-forward of the acceleration), so its tracking error is larger than the station's; any diagram
that takes a desired state [q; q̇] can take the same source.
"""

import sys
from pathlib import Path

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlant
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.analysis import Simulator
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource

from drake_traj import SimulationResult, get_robot
from drake_traj.results import ResultFileError
from drake_traj.scenario import default_plant_config

# the main job's folders: the README's `drake-traj run --out out`, and `drake-traj run` without --out
MAIN_JOB_FOLDERS = ("out", "out/pajak_sim3")


def replay(run_dir) -> float:
    """Replays the reference of ``run_dir``; returns the largest joint tracking error [rad]."""
    result = SimulationResult.load(run_dir)
    trajectory = result.reference_trajectory()  # cubic Hermite through the logged q_ref, qd_ref
    robot = get_robot(result.robot or "ur10e")
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(default_plant_config(), builder)
    instance = robot.add_to_plant(plant)
    for name, kp, kd in zip(robot.joint_names, *robot.default_gains):
        plant.GetJointActuatorByName(f"{name}_actuator", instance).set_controller_gains(PdControllerGains(p=kp, d=kd))
    plant.Finalize()
    plant.SetDefaultPositions(instance, trajectory.value(0.0).ravel())
    source = builder.AddSystem(TrajectorySource(trajectory, output_derivative_order=1))  # [q; q̇]
    builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(instance))
    gravity = builder.AddSystem(InverseDynamics(plant, InverseDynamics.InverseDynamicsMode.kGravityCompensation))
    builder.Connect(plant.get_state_output_port(instance), gravity.get_input_port_estimated_state())
    builder.Connect(gravity.get_output_port_generalized_force(), plant.get_actuation_input_port(instance))
    logger = LogVectorOutput(plant.get_state_output_port(instance), builder, 1e-3)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(trajectory.end_time())
    log = logger.FindLog(simulator.get_context())
    desired = np.array([trajectory.value(t).ravel() for t in log.sample_times()])
    error = float(np.abs(log.data()[: robot.num_joints].T - desired).max())
    print(f"replayed {result.name!r} ({trajectory.end_time():.3f} s): largest joint tracking error {error:.2e} rad")
    return error


def main(argv: list[str]) -> int:
    """Replays the run of ``argv[0]`` or of the main job's folder; returns the exit code (2: no run
    there, said in one line)."""
    if argv:
        run_dir = argv[0]
    else:
        run_dir = next((folder for folder in MAIN_JOB_FOLDERS if (Path(folder) / "result.npz").is_file()), None)
        if run_dir is None:
            print(f"replay_reference.py: no run in {' or '.join(MAIN_JOB_FOLDERS)} (in {Path.cwd()}): "
                  "`drake-traj run --out out` writes one; or give a run's folder: "
                  "python examples/replay_reference.py RUN_DIR", file=sys.stderr)
            return 2
    try:
        replay(run_dir)
    except ResultFileError as error:
        print(f"replay_reference.py: {error} (`drake-traj run --out {run_dir}` writes a run there)", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
