"""An external disturbance: a torque pulse on the plant's joints, and how the PD loop recovers.

    python diagrams/disturbance.py [OUT_DIR] [--scenario NAME] [--joint J] [--torque TAU]

A square pulse of ``--torque`` N m (default 60) on joint ``--joint`` (default 2, the shoulder)
for 100 ms from 1.0 s enters the station's ``applied_generalized_force`` input. The reference is
not changed; the arm is pushed off it and the PD controller with feed-forward brings it back.
Writes the usual figures and ``disturbance.png``: the pulse, the joint tracking error and the
TCP tracking error.
"""

import argparse

import numpy as np
from matplotlib.figure import Figure
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from drake_traj import SimulationResult, get_robot, load_scenario, make_station, run_station
from drake_traj.scenario import find_scenario

START, LENGTH = 1.0, 0.1  # [s]


def torque_pulse(num_joints: int, joint: int, torque: float) -> PiecewisePolynomial:
    """``torque`` [N m] on ``joint`` (0-based) from START for LENGTH [s], zero otherwise."""
    values = np.zeros((num_joints, 4))
    values[joint, 1] = torque
    return PiecewisePolynomial.ZeroOrderHold([0.0, START, START + LENGTH, START + LENGTH + 1.0], values)


def main(argv=None) -> SimulationResult:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="out/disturbance")
    parser.add_argument("--scenario", default="quintic_ptp", help="a shipped scenario's name or a YAML file")
    parser.add_argument("--joint", type=int, default=2, help="the joint pushed, 1-based (default 2)")
    parser.add_argument("--torque", type=float, default=60.0, help="the pulse's torque [N m] (default 60)")
    args = parser.parse_args(argv)
    scenario = load_scenario(*find_scenario(args.scenario))
    robot = get_robot(scenario.robot)
    if not 1 <= args.joint <= robot.num_joints:
        parser.error(f"--joint must be 1 to {robot.num_joints}, got {args.joint}")

    builder = DiagramBuilder()
    station = builder.AddSystem(make_station(scenario))
    pulse = builder.AddNamedSystem("torque_pulse", TrajectorySource(torque_pulse(robot.num_joints, args.joint - 1, args.torque)))
    builder.Connect(pulse.get_output_port(), station.GetInputPort("applied_generalized_force"))
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(scenario.simulator, simulator)
    failure = run_station(simulator, station, settle_time=scenario.settle_time, max_duration=scenario.max_duration)
    # The pulse pushes the TCP centimetres off on purpose: a tolerance of 5 cm instead of 5 mm keeps
    # the run a success while it shows the recovery (a saturated drive still fails it).
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                           name="disturbance", failure=failure, tracking_tolerance=0.05)

    result.save(args.out, overwrite=True)  # this script's own folder: a rerun replaces its run
    result.save_figures(args.out)
    joint_error = 1e3 * (result.q_ref[:, args.joint - 1] - result.q_meas[:, args.joint - 1])
    tcp_error = 1e3 * np.linalg.norm(result.tcp_ref[:, :3] - result.tcp[:, :3], axis=1)
    figure = Figure(figsize=(9, 6), layout="constrained")
    torque_ax, joint_ax, tcp_ax = figure.subplots(3, 1, sharex=True)
    torque_ax.plot(result.t, np.where((result.t >= START) & (result.t < START + LENGTH), args.torque, 0.0))
    torque_ax.set_ylabel(f"pulse on joint {args.joint} [N m]")
    joint_ax.plot(result.t, joint_error)
    joint_ax.set_ylabel(f"joint {args.joint} error [mrad]")
    tcp_ax.plot(result.t, tcp_error)
    tcp_ax.set_ylabel("TCP error [mm]")
    tcp_ax.set_xlabel("t [s]")
    for ax in (torque_ax, joint_ax, tcp_ax):
        ax.axvspan(START, START + LENGTH, color="tab:orange", alpha=0.15)
        ax.grid(True, alpha=0.3)
    figure.suptitle(f"{scenario.name}: a {args.torque:g} N m pulse on joint {args.joint} for {1e3 * LENGTH:.0f} ms")
    figure.savefig(f"{args.out}/disturbance.png", dpi=110)
    after = result.t >= START + LENGTH
    recovered = result.t[after][np.argmax(tcp_error[after] < 0.1)]  # back within 0.1 mm
    print(f"peak TCP error {tcp_error.max():.2f} mm at t = {result.t[np.argmax(tcp_error)]:.3f} s; back within "
          f"0.1 mm at t = {recovered:.3f} s ({1e3 * (recovered - START - LENGTH):.0f} ms after the pulse); "
          f"succeeded: {result.succeeded}")
    return result


if __name__ == "__main__":
    main()
