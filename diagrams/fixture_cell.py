"""A UR10e in its cell: a gripper with a 3 kg part moves over a fixture on the table
(``fixture_cell.yaml``), checked before it moves, then simulated with the cell in the plant.

    python diagrams/fixture_cell.py [OUT_DIR]

1. The planned motion (``planner.plan()``) is checked in the cell: joint ranges, self-collision,
   the table, the fixture and the post, with the scenario's 10 mm clearance; the script prints
   how close the gripper and the arm come to the fixture.
2. The station (``make_station``: the table, fixture, post, gripper and payload are in the
   plant) runs under the scenario's integrator, drawn in Meshcat; writes the usual figures and
   ``meshcat.html`` with the cell.
3. The same task with the fixture 0.3 m taller is refused before the motion:
   ``refusal.png`` shows the configuration, and the error names the time, the two bodies, the
   distance and the waypoint.
"""

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator

from drake_traj import SimulationResult, load_scenario, make_planner, make_station, run_station
from drake_traj.cell import CollisionError, refusal_figure
from drake_traj.station import export_html
from drake_traj.scenario import check_in_cell

SCENARIO = Path(__file__).with_name("fixture_cell.yaml")


def nearest_to(scenario, planner, body: str) -> tuple[float, float]:
    """(distance [m], time [s]) of the nearest approach of anything to ``body`` along the plan,
    at the check's own sample times."""
    checker = scenario.cell_checker()
    plan = planner.plan()
    best = (np.inf, np.nan)
    for t in checker.check(plan).times:
        for contact in checker.contacts(plan.value(t).ravel(), within=0.5):
            if body in contact.bodies and contact.distance < best[0]:
                best = (contact.distance, float(t))
    return best


def main(argv=None) -> SimulationResult:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="out/fixture_cell")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scenario = load_scenario(SCENARIO)

    check = check_in_cell(scenario, make_planner(scenario))  # raises CollisionError / JointRangeError
    distance, when = nearest_to(scenario, make_planner(scenario), "fixture")
    print(f"checked {len(check.times)} configurations (no point moves more than {check.spacing * 1000:g} mm between "
          f"them); nearest to the fixture: {distance * 1000:.1f} mm at t = {when:.3f} s")

    meshcat = Meshcat()
    station = make_station(scenario, meshcat=meshcat)
    simulator = Simulator(station)
    ApplySimulatorConfig(scenario.simulator, simulator)
    visualizer = station.GetSubsystemByName("visualizer")
    visualizer.StartRecording(False)
    failure = run_station(simulator, station, settle_time=scenario.settle_time, max_duration=scenario.max_duration)
    visualizer.StopRecording()
    visualizer.PublishRecording()
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                           name=scenario.name, failure=failure)
    result.save(out, overwrite=True)  # this script's own folder: a rerun replaces its run
    result.save_figures(out)
    export_html(meshcat, out / "meshcat.html")
    metrics = result.metrics()
    print(f"{scenario.name}: T = {metrics.duration_s:.3f} s, TCP tracking error {metrics.tracking_error_tcp_max_m * 1000:.3f} "
          f"mm, succeeded: {result.succeeded}")

    taller = dataclasses.replace(scenario.cell.obstacles[0], size=[0.25, 0.25, 0.50], xyz=[-0.45, -0.55, 0.25])
    blocked = dataclasses.replace(scenario, cell=dataclasses.replace(scenario.cell, obstacles=[taller]))
    try:
        check_in_cell(blocked, make_planner(blocked))
    except CollisionError as error:
        refusal_figure(blocked.cell_checker(), error).savefig(out / "refusal.png", dpi=100)
        print(f"with a 0.5 m fixture: refused: {error}")
    return result


if __name__ == "__main__":
    main()
    sys.exit(0)
