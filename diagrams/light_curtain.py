"""A light curtain slows the arm while a person is inside the cell: a user's own LeafSystem on
the station's ``speed_override`` input.

    python diagrams/light_curtain.py [OUT_DIR] [--scenario NAME]

The person (simulated) enters the curtain at 1.5 s and leaves at 3.5 s; while they are inside
the curtain asks for 25 % speed, then 100 % again. The planner's scaling coefficient c follows the
request smoothly (eq. 18 of Pająk 2024, with a jerk-limited rate), so q̈ stays continuous and the
joint limits hold. Writes the usual figures and ``light_curtain.png`` (the request and c).
"""

import argparse
import sys

import numpy as np
from matplotlib.figure import Figure
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from drake_traj import SimulationResult, load_scenario, make_station, run_station
from drake_traj.scenario import find_scenario


class LightCurtain(LeafSystem):
    """Outputs the speed override a light curtain asks for: ``slow`` while a person is inside
    (from ``enter`` to ``leave`` [s]), 1 otherwise."""

    def __init__(self, enter: float, leave: float, slow: float = 0.25):
        super().__init__()
        self.enter, self.leave, self.slow = enter, leave, slow
        self.DeclareVectorOutputPort("speed_override", 1, self._request)

    def inside(self, t: float) -> bool:
        return self.enter <= t < self.leave

    def _request(self, context, output):
        output.SetAtIndex(0, self.slow if self.inside(context.get_time()) else 1.0)


def main(argv=None) -> SimulationResult:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="out/light_curtain")
    parser.add_argument("--scenario", default="quintic_ptp", help="a shipped scenario's name or a YAML file")
    args = parser.parse_args(argv)
    scenario = load_scenario(*find_scenario(args.scenario))

    builder = DiagramBuilder()
    station = builder.AddSystem(make_station(scenario))
    curtain = builder.AddNamedSystem("light_curtain", LightCurtain(enter=1.5, leave=3.5))
    builder.Connect(curtain.get_output_port(), station.GetInputPort("speed_override"))
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(scenario.simulator, simulator)
    failure = run_station(simulator, station, settle_time=scenario.settle_time, max_duration=scenario.max_duration)
    result = SimulationResult.from_station(station, station.GetMyContextFromRoot(simulator.get_context()),
                                           name="light_curtain", failure=failure)

    result.save(args.out, overwrite=True)  # this script's own folder: a rerun replaces its run
    result.save_figures(args.out)
    figure = Figure(figsize=(8, 3.5), layout="constrained")
    ax = figure.subplots()
    ax.plot(result.t, [curtain.slow if curtain.inside(t) else 1.0 for t in result.t], label="light curtain's request")
    ax.plot(result.t, result.scaling, label="scaling coefficient c")
    ax.axvspan(curtain.enter, curtain.leave, color="tab:orange", alpha=0.15, label="person inside")
    ax.set_xlabel("t [s]")
    ax.set_ylim(0.0, 1.05)
    figure.legend(loc="outside upper center", ncol=3)
    figure.savefig(f"{args.out}/light_curtain.png", dpi=110)
    steps = np.abs(np.diff(result.qdd_ref[1:], axis=0)).max()
    metrics = result.metrics()
    print(f"{scenario.name} with a light curtain: T = {metrics.duration_s:.3f} s, largest q̈ step between 1 ms "
          f"samples {steps:.4f} rad/s², max |q̈| / limit {metrics.max_acceleration_over_limit:.4f}, "
          f"succeeded: {result.succeeded}")
    return result


if __name__ == "__main__":
    main()
    sys.exit(0)
