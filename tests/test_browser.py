"""A real browser opens the exported Meshcat recording and the arm is on screen.

Headless Chromium (Debian package ``chromium``) renders meshcat.html with software WebGL; we
count pixels of the arm's blue joint housings (rgba 0.2 0.4 0.9 in models/ur10e.urdf), of the
red TCP path and of the orange waypoint spheres, against an empty Meshcat scene as the control.
"""

import os

import pytest
from pydrake.geometry import Meshcat

import browser
from drake_traj.meshcat import export_html

CHROMIUM = browser.find_chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("CI"), reason="chromium not installed (CI installs it)"
)


def red_pixels(png):
    rgb = browser._read_rgb(png).astype(int)
    return int(((rgb[..., 0] > 150) & (rgb[..., 1] < 90) & (rgb[..., 2] < 90)).sum())


@pytest.fixture(scope="module")
def empty_scene_png(tmp_path_factory):
    directory = tmp_path_factory.mktemp("empty_scene")
    html = export_html(Meshcat(), directory / "empty.html")
    return browser.screenshot_html(html, directory / "empty.png")


def test_exported_recording_shows_the_arm_and_its_path(quintic_run_dir, empty_scene_png, tmp_path):
    assert CHROMIUM is not None, "CI must install chromium"
    # A budget longer than the 6.7 s recording: the last frame (arm at rest at its goal) is held.
    png = browser.screenshot_html(quintic_run_dir / "meshcat.html", tmp_path / "run.png", virtual_time_ms=10_000)
    arm = browser.blue_pixel_fraction(png)
    empty = browser.blue_pixel_fraction(empty_scene_png)
    # Measured: about 0.5 % blue with the arm, 0.016 % (the world axes) without.
    assert empty < 0.0005
    assert arm > 0.002, f"only {arm:.4%} arm-blue pixels: the arm is not drawn"
    assert red_pixels(png) > 200 > red_pixels(empty_scene_png)
