"""A run's figures: written as files, the TCP error they plot [mm] as computed here from the
logged arrays, and a planner without trajectory scaling said to have none."""

import dataclasses

import numpy as np
import pytest

from drake_traj import SimulationResult

FIGURES = ("joints", "tracking", "scaling", "tcp_path")


@pytest.fixture(scope="module")
def quintic(quintic_run_dir) -> SimulationResult:
    return SimulationResult.load(quintic_run_dir)


def tcp_error_mm(result: SimulationResult) -> np.ndarray:
    """Our own computation: the Euclidean distance of the logged TCP positions, in mm."""
    difference = result.tcp_ref[:, :3] - result.tcp[:, :3]
    return 1e3 * np.sqrt(np.sum(difference**2, axis=1))


def tcp_error_line(figure):
    lines = [line for ax in figure.axes for line in ax.get_lines() if line.get_label().startswith("|p_ref - p_meas|")]
    assert len(lines) == 1, [line.get_label() for ax in figure.axes for line in ax.get_lines()]
    return lines[0]


def test_the_figures_are_written(quintic, tmp_path):
    paths = quintic.save_figures(tmp_path)
    assert [path.name for path in paths] == [f"{stem}.png" for stem in FIGURES]
    assert all(path.stat().st_size > 20_000 for path in paths)


@pytest.mark.parametrize("figure", ["tracking_figure", "tcp_path_figure"])
def test_the_plotted_tcp_error_is_the_logged_distance_in_mm(quintic, figure):
    line = tcp_error_line(getattr(quintic, figure)())
    np.testing.assert_array_equal(line.get_xdata(), quintic.t)
    np.testing.assert_allclose(line.get_ydata(), tcp_error_mm(quintic), rtol=1e-12, atol=1e-12)
    worst = int(np.argmax(tcp_error_mm(quintic)))
    assert line.get_label() == (f"|p_ref - p_meas|, max {tcp_error_mm(quintic)[worst]:.3g} mm "
                                f"at t = {quintic.t[worst]:.3f} s")
    assert tcp_error_mm(quintic)[worst] == pytest.approx(1e3 * quintic.metrics().tracking_error_tcp_max_m)
    assert 0.0 < tcp_error_mm(quintic)[worst] < 0.5  # the PD loop's: far below what the 3-D view resolves


def test_the_tracking_figure_has_the_tcp_error_beside_the_joints(quintic):
    error_ax, tcp_ax, torque_ax = quintic.tracking_figure().axes
    assert error_ax.get_ylabel() == "q_ref - q_meas [mrad]" and tcp_ax.get_ylabel() == "TCP position error [mm]"
    assert torque_ax.get_ylabel() == "effort / effort limit"


def notes(figure) -> list[str]:
    return [text.get_text() for ax in figure.axes for text in ax.texts]


def test_a_constant_scaling_is_said_to_be_no_scaling(quintic):
    assert np.all(quintic.scaling == 1.0)  # the quintic planner runs its plan as timed
    assert notes(quintic.scaling_figure()) == ["no trajectory scaling: constant 1"]
    scaled = dataclasses.replace(quintic, scaling=np.linspace(0.0, 1.0, len(quintic.t)))
    assert notes(scaled.scaling_figure()) == []
