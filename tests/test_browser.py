"""A real browser opens the exported Meshcat recording, and the live view, and the arm is on screen.

Headless Chromium (Debian package ``chromium``) renders meshcat.html with software WebGL; we
count pixels of the arm's blue joint housings (rgba 0.2 0.4 0.9 in models/ur10e.urdf), of the
red TCP path and of the orange waypoint spheres, against an empty Meshcat scene as the control.
"""

import os
import subprocess
import sys
import time

import pytest
from pydrake.geometry import Meshcat

import browser
from drake_traj.station import export_html

CHROMIUM = browser.find_chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("CI"), reason="chromium is not installed: install it first (Debian, as root or with sudo: apt-get update && apt-get install -y chromium; .ci/run does)"
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


def orange_pixels(png):
    rgb = browser._read_rgb(png).astype(int)
    return int(((rgb[..., 0] > 150) & (rgb[..., 1] > 70) & (rgb[..., 1] < 170) & (rgb[..., 2] < 90)).sum())


def loaded_screenshots(url, folder, process, count: int = 2, spacing_s: float = 20.0) -> list:
    """``count`` screenshots of a live page, taken at least ``spacing_s`` seconds apart while
    ``process`` (the run serving it) is still moving the arm, each once the page has loaded the
    whole scene (the arm's blue and the task's orange are on it). A fresh headless page does not
    always have the scene within its wait: measured here, 2 of 6 pages 5 s after the start, and in
    CI the arm alone (79 orange pixels), so shots without the scene are retaken while the motion
    lasts."""
    shots = []
    last_shot = -float("inf")
    for attempt in range(20):
        if len(shots) == count or process.poll() is not None:
            break
        time.sleep(max(0.0, last_shot + spacing_s - time.monotonic()))
        started = time.monotonic()
        try:
            png = browser.screenshot_url(url, folder / f"live_{attempt}.png", wait_ms=5000)
        except RuntimeError as error:  # seen in CI: the page refused as the run wrote its files
            print(f"live screenshot {attempt} failed: {str(error)[:200]}")
            continue
        if browser.blue_pixel_fraction(png) > 0.002 and orange_pixels(png) > 100 and process.poll() is None:
            shots.append(png)
            last_shot = started
    assert len(shots) == count, f"only {len(shots)} of {count} live screenshots showed the scene during the motion"
    return shots


def test_live_view_shows_the_arm_the_task_and_a_growing_trail(tmp_path):
    assert CHROMIUM is not None, "CI must install chromium"
    port = browser.free_port()
    out = tmp_path / "live"
    # A tenth of real time: the 5.3 s motion of Pająk 2024 sim 3 takes 53 s, time for several
    # screenshots (5-8 s each); no terminal, and --serve-after 0: it exits once the run's files
    # are written.
    process = subprocess.Popen(
        [sys.executable, "-m", "drake_traj.cli", "run", "pajak_sim3", "--out", str(out), "--meshcat",
         "--port", str(port), "--rate", "0.1", "--wait-timeout", "120", "--serve-after", "0"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        waiting = browser.read_until(process.stderr, "waiting up to", timeout=120)
        assert f"http://localhost:{port}" in waiting
        # The first browser to connect starts the motion; two more screenshots catch it mid-way,
        # 20 s apart (2 s of motion): the trail 1 s into the motion is only 0-10 red pixels.
        browser.screenshot_url(f"http://localhost:{port}", tmp_path / "start.png", wait_ms=1000)
        early, later = loaded_screenshots(f"http://localhost:{port}", tmp_path, process)
        stdout, stderr = process.communicate(timeout=180)
    finally:
        process.kill()
    assert process.returncode == 0, stderr
    final = browser.screenshot_html(out / "meshcat.html", tmp_path / "final.png", virtual_time_ms=20_000)
    for png in (early, later):  # the arm and the task (the goals' neighbourhoods, orange)
        assert browser.blue_pixel_fraction(png) > 0.002
        assert orange_pixels(png) > 100
    # The trail grows with the motion and is part of the final path.
    trail = [red_pixels(png) for png in (early, later, final)]
    assert trail[0] < trail[1] < 0.9 * trail[2] and trail[1] > 50, f"red trail pixels (early, later, final): {trail}"

