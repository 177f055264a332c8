"""The generic path on the UR10e agrees with the analytic UR10e: a ChainArm from the
DH table of docs/ur10e.md (simulated with models/ur10e.urdf) and a ChainArm read from
models/ur10e.urdf through MultibodyPlant run Pająk 2024's simulations 1-3 to the analytic arm's
Table 2 finish times, through the compiled integration and, for sim 3, the closed-loop station.
FK, Jacobian and the DH chain's IK against the closed form are in test_chain.py; here the
plant-built arm's IK."""

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from drake_traj.planners import make_planner
from drake_traj.planners.pajak import PajakLaw
from drake_traj.planners.pajak.integration import integrate
from drake_traj.robots import ur10e
from drake_traj.robots.chain_arm import ChainArm
from drake_traj.robots.task_space import wrap_angle
from drake_traj.scenario import load_scenario
from drake_traj.station import simulate

from conftest import DIAGRAMS

# docs/ur10e.md, "Kinematics: standard DH": rows [d, a, alpha, theta offset] [m, rad]
DOCS_DH = np.array([[0.1807, 0.0, np.pi / 2, 0.0], [0.0, -0.6127, 0.0, 0.0], [0.0, -0.57155, 0.0, 0.0],
                    [0.17415, 0.0, np.pi / 2, 0.0], [0.11985, 0.0, -np.pi / 2, 0.0], [0.11655, 0.0, 0.0, 0.0]])
# T [s] of the analytic UR10e's sims 1-3 (README "Pająk 2024: Table 2", our method; paper 4.98 / 5.22 / 5.32)
TABLE2_ANALYTIC = {"sim1": 5.116, "sim2": 5.069, "sim3": 5.332}
AGREEMENT = 1e-3  # relative: 0.1 %


def dh_arm():
    return ChainArm.from_dh("ur10e_dh", DOCS_DH, model_file=ur10e.model_path(), acceleration_limits=1.4,
                            home=ur10e.HOME)


def urdf_arm():
    return ChainArm.from_model_file(ur10e.model_path(), name="generic_ur10e", base_frame="base", tool_frame="tool0",
                                    acceleration_limits=1.4, home=ur10e.HOME)


ARMS = {"dh": dh_arm, "urdf": urdf_arm}


@pytest.mark.parametrize("sim", sorted(TABLE2_ANALYTIC))
@pytest.mark.parametrize("kind", sorted(ARMS))
def test_integrated_table_2_times_are_the_analytic_arms(kind, sim):
    config = load_scenario(DIAGRAMS / "pajak.yaml", sim).planner
    generic = integrate(PajakLaw(config, ARMS[kind]()), ur10e.HOME)
    analytic = integrate(PajakLaw(config, ur10e.UR10E), ur10e.HOME)
    assert analytic["T"] == pytest.approx(TABLE2_ANALYTIC[sim], abs=5e-4)
    assert generic["T"] == pytest.approx(analytic["T"], rel=AGREEMENT)
    assert generic["T"] == pytest.approx(TABLE2_ANALYTIC[sim], rel=AGREEMENT)
    # measured: the same steps, the joint motions equal to 9e-16 rad
    assert len(generic["q"]) == len(analytic["q"])
    np.testing.assert_allclose(generic["q"], analytic["q"], atol=1e-9, rtol=0)


@pytest.mark.parametrize("kind", sorted(ARMS))
def test_closed_loop_sim3_on_the_generic_arm(kind):
    arm = ARMS[kind]()
    planner = make_planner(load_scenario(DIAGRAMS / "pajak.yaml", "sim3").planner, arm, ur10e.HOME)
    result = simulate(planner, name=f"sim3_{kind}")
    assert result.succeeded, result.failure
    assert result.robot == arm.name
    assert result.duration == pytest.approx(TABLE2_ANALYTIC["sim3"], rel=AGREEMENT)
    assert np.abs(result.qd_ref).max() <= 1.05 + 1e-9 and np.abs(result.qdd_ref).max() <= 1.40 + 1e-9
    assert np.linalg.norm(ur10e.task_pose(result.q_meas[-1])[:3] - planner.goal_pose()[:3]) < 1e-3


def test_plant_built_arm_ik_is_the_closed_forms():
    """The arm read from a user's plant (the URDF parsed into it) finds every closed-form IK
    solution, each to 1e-9 rad, and every solution it finds puts the flange at the pose."""
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(ur10e.model_path()))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base"))
    plant.Finalize()
    arm = ChainArm.from_plant(plant, name="generic_ur10e", base_frame="base", tool_frame="tool0", acceleration_limits=1.4)
    rng = np.random.default_rng(24)
    for _ in range(4):
        pose = ur10e.task_pose(rng.uniform(-np.pi, np.pi, 6))
        expected, found = ur10e.inverse_kinematics_all(pose), arm.inverse_kinematics_all(pose)
        assert len(expected) == 8
        for q in expected:
            assert min(np.max(np.abs(wrap_angle(q - other))) for other in found) < 1e-9
        for q in found:
            error = ur10e.task_pose(q) - pose
            error[3:] = wrap_angle(error[3:])
            assert np.max(np.abs(error)) < 1e-9
