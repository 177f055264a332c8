"""metrics.json and the run's printout: the renamed metrics with their old names kept for one release,
and every float rounded to what it measures (docs/results.md, "Renamed metrics")."""

import contextlib
import io
import json
import math

import pytest

from drake_traj import cli
from drake_traj.results import SimulationResult, round_angle, round_fraction, round_length, round_time, round_torque

OLD_TO_NEW = {"max_velocity_over_limit": "peak_velocity_fraction",
              "max_acceleration_over_limit": "peak_acceleration_fraction",
              "peak_torque_over_limit": "peak_torque_fraction"}
# Decimals each float metric keeps: times [s] and lengths [m] 6 (1 µs, 1 µm), angles and joint rates
# 6, ratios 4, torques [N m] 4, masses [kg] and densities [kg/m³] 6.
DECIMALS = {"duration_s": 6, "log_period_s": 6, "simulated_time_s": 6, "wall_time_s": 6, "planning_time_s": 6,
            "time_at_effort_limit_s": 6, "qd_min": 6, "qd_max": 6, "qdd_min": 6, "qdd_max": 6, "max_jerk": 6,
            "tracking_error_joint_max_rad": 6, "final_orientation_error_rad": 6, "locked_joints": 6,
            "tracking_error_tcp_max_m": 6, "final_position_error_m": 6, "peak_velocity_fraction": 4,
            "peak_acceleration_fraction": 4, "peak_torque_fraction": 4, "real_time_factor": 4, "peak_torque_nm": 4,
            "estimated_inertia_links": 6, "estimated_inertia_density": 6} | {old: 4 for old in OLD_TO_NEW}

SHORT_MOVE = """\
name: short_quintic
q_initial: [-1.5707963267948966, -1.5707963267948966, -2.356194490192345, -0.7853981633974483, 1.5707963267948966, 0.7853981633974483]
planner: !QuinticConfig
  goals:
    - [-1.3, -1.7, -2.2, -0.9, 1.7, 0.9]
  velocity_limit: [1.05, 1.05, 1.05, 1.05, 1.05, 1.05]
  acceleration_limit: [1.40, 1.40, 1.40, 1.40, 1.40, 1.40]
settle_time: 0.013
"""


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """(the summary ``drake-traj run`` prints, its metrics.json, its result) of a short quintic move
    settling 13 ms."""
    folder = tmp_path_factory.mktemp("short_run")
    (folder / "short.yaml").write_text(SHORT_MOVE)
    with contextlib.redirect_stdout(io.StringIO()) as out:
        assert cli.main(["run", str(folder / "short.yaml"), "--out", str(folder / "out")]) == 0
    printed = out.getvalue()
    return (json.loads(printed[:printed.index("\nwrote ")]), json.loads((folder / "out" / "metrics.json").read_text()),
            SimulationResult.load(folder / "out"))


def _floats(value):
    """Each float in ``value`` (a float, a list or a dict of them)."""
    if isinstance(value, float):
        yield value
    elif isinstance(value, (list, dict)):
        for item in value.values() if isinstance(value, dict) else value:
            yield from _floats(item)


def test_metrics_json_and_the_printout_round_each_float_to_its_kind(short_run):
    printed, saved, result = short_run
    full = result.metrics()  # full precision, from result.npz
    assert saved["duration_s"] > 0.5 and saved["succeeded"]
    checked = 0
    for key, value in saved.items():
        for number in _floats(value):
            assert key in DECIMALS, f"{key} holds the float {number} of no known kind"
            assert round(number, DECIMALS[key]) == number, f"{key}: {number} has more than {DECIMALS[key]} decimals"
            checked += 1
    assert checked > 40
    for key in ("duration_s", "wall_time_s", "tracking_error_tcp_max_m", "max_jerk", "peak_velocity_fraction"):
        assert saved[key] == round(getattr(full, key), DECIMALS[key]), key
    assert saved["peak_torque_nm"] == [round(value, 4) for value in full.peak_torque_nm]
    assert saved["real_time_factor"] == round(full.simulated_time_s / full.wall_time_s, 4)
    assert printed == {key: saved[key] for key in printed}  # the printout is metrics.json's, rounded alike
    assert "peak_velocity_fraction" in printed and not set(printed) & set(OLD_TO_NEW)


def test_the_old_names_hold_the_new_names_values(short_run):
    _, saved, result = short_run
    full = result.metrics()
    for old, new in OLD_TO_NEW.items():
        assert saved[old] == saved[new], old
        assert getattr(full, old) == getattr(full, new), old  # the Python attribute too
    # what the new names hold: the peaks of |q̇|, |q̈| (over joints) and |τ| (per joint) over their limits
    assert full.peak_velocity_fraction == pytest.approx(max(abs(result.qd_ref).max(axis=0) / result.velocity_limit))
    assert full.peak_torque_fraction == pytest.approx(list(abs(result.tau).max(axis=0) / result.effort_limit))
    assert full.peak_acceleration_fraction == pytest.approx(
        max(abs(result.qdd_ref).max(axis=0) / result.acceleration_limit))
    # a short quintic move: its limiting joint touches the acceleration limit (between 1 ms samples), not the
    # velocity limit
    assert full.peak_acceleration_fraction == pytest.approx(1.0, abs=1e-5) and 0.3 < full.peak_velocity_fraction < 0.9
    with pytest.raises(AttributeError, match="no attribute 'max_speed'"):
        full.max_speed  # noqa: B018


def test_the_rounding_of_each_kind():
    assert json.dumps(round_time(5.1160000000000005)) == "5.116"
    assert round_time(6.177048330634682) == 6.177048
    assert round_length([2.84e-5 + 1e-12, float("nan")])[0] == 2.8e-5 and math.isnan(round_length([float("nan")])[0])
    assert round_angle({"joint": -0.0000001}) == {"joint": 0.0} and math.copysign(1, round_angle(-1e-9)) == 1
    assert round_fraction(0.99996) == 1.0 and round_fraction(0.123456) == 0.1235
    assert round_torque([67.412345678, None]) == [67.4123, None]
    assert round_time(None) is None and round_time(3) == 3  # an int (a count) is not a float to round
