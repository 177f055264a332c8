"""Headless-Chromium helpers for tests that inspect exported Meshcat HTML.

``pydrake.geometry.Meshcat.StaticHtml()`` writes a self-contained page (three.js
is inlined, no network needed).  These helpers render such a page with a headless
Chromium using SwiftShader, Chromium's software WebGL, so they work on machines
without a GPU or a display, and then measure the screenshot's pixels.

Meshcat recordings (``MeshcatVisualizer.PublishRecording()``) start playing when
the page loads.  The animation runs on Chromium's virtual clock, so with a
virtual-time budget longer than the recording the screenshot shows its last frame;
with a shorter budget it shows an intermediate frame.
"""

from __future__ import annotations

import os
import queue
import shutil
import signal
import socket
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from PIL import Image

_CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")

_CHROMIUM_FLAGS = (
    "--headless=new",
    # Chromium refuses to start as root (containers, CI) with its sandbox on.
    "--no-sandbox",
    # Software WebGL, chosen explicitly: Chromium's automatic fallback to it on
    # GPU-less machines is deprecated.
    "--use-gl=angle",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    # Containers often have a tiny /dev/shm; use /tmp for shared memory.
    "--disable-dev-shm-usage",
    # The machine may be offline: do not try to reach Google services.
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
    "--no-default-browser-check",
    "--hide-scrollbars",
)


def find_chromium() -> str | None:
    """Return the path of a Chromium or Chrome executable on PATH, or None."""
    for name in _CHROMIUM_NAMES:
        path = shutil.which(name)
        if path is not None:
            return path
    return None


def free_port() -> int:
    """A TCP port nobody listens on now (for a Meshcat server of a test)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def read_until(stream, text: str, *, timeout: float) -> str:
    """Read ``stream`` line by line (in a thread: a buffered pipe and select() do not mix) until a
    line contains ``text``; returns what was read. Raises RuntimeError (with what was read) at EOF
    or after ``timeout`` [s]."""
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in iter(stream.readline, "")] + [lines.put(None)],
                     daemon=True).start()
    deadline = time.monotonic() + timeout
    seen = []
    while (remaining := deadline - time.monotonic()) > 0:
        try:
            line = lines.get(timeout=remaining)
        except queue.Empty:
            break
        if line is None:
            break
        seen.append(line)
        if text in line:
            return "".join(seen)
    raise RuntimeError(f"{text!r} not seen within {timeout} s; got:\n{''.join(seen)}")


def screenshot_url(url: str, png_path, *, wait_ms: int = 4000, **kwargs) -> Path:
    """Screenshot of a page served at ``url`` (e.g. a live Meshcat) after ``wait_ms`` of real
    time: a live page never goes idle, so a virtual-time budget would never run out."""
    return screenshot_html(url, png_path, real_time_ms=wait_ms, **kwargs)


def screenshot_html(
    html_path: str | os.PathLike,
    png_path: str | os.PathLike,
    *,
    width: int = 1280,
    height: int = 800,
    timeout: float = 120,
    virtual_time_ms: int = 5000,
    real_time_ms: int | None = None,
) -> Path:
    """Render an HTML file in headless Chromium and save a PNG screenshot.

    Args:
        html_path: The page to open, e.g. a file written from Meshcat.StaticHtml(), or an
            http:// URL (a live Meshcat).
        png_path: Where to write the screenshot; an existing file is replaced.
        width: Window width in pixels.
        height: Window height in pixels.
        timeout: Seconds to wait for Chromium before killing it.
        virtual_time_ms: Virtual time, in milliseconds, the page may run before the
            screenshot is taken.  Chromium fast-forwards idle time, so a long
            budget costs little; a Meshcat recording shorter than the budget is
            captured at its final frame.  Must be positive (a zero budget makes
            Chromium wait forever).
        real_time_ms: Instead of the virtual-time budget, take the screenshot after this many
            milliseconds of real time (for a live page).

    Returns:
        The absolute path of the PNG.

    Raises:
        FileNotFoundError: If ``html_path`` does not exist.
        ValueError: If ``virtual_time_ms`` is not positive.
        RuntimeError: If no Chromium is found, Chromium times out, or no PNG is
            written.  The message includes Chromium's stderr.
    """
    page = str(html_path) if str(html_path).startswith("http") else Path(html_path).resolve(strict=True).as_uri()
    png = Path(png_path).resolve()
    if virtual_time_ms <= 0:
        raise ValueError(f"virtual_time_ms must be positive, got {virtual_time_ms}")
    chromium = find_chromium()
    if chromium is None:
        raise RuntimeError(f"none of {', '.join(_CHROMIUM_NAMES)} found on PATH")
    png.unlink(missing_ok=True)
    with tempfile.TemporaryDirectory(prefix="chromium-profile-", ignore_cleanup_errors=True) as profile:
        command = [
            chromium,
            *_CHROMIUM_FLAGS,
            f"--user-data-dir={profile}",
            f"--window-size={width},{height}",
            f"--timeout={real_time_ms}" if real_time_ms else f"--virtual-time-budget={virtual_time_ms}",
            f"--screenshot={png}",
            page,
        ]
        # Chromium's helper processes inherit its output pipes, so on a timeout
        # the whole process group must be killed for the pipes to close.
        process = subprocess.Popen(
            command,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        try:
            _, stderr = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            _, stderr = process.communicate()
            raise RuntimeError(f"Chromium timed out after {timeout} s:\n{stderr}") from None
    if not png.is_file() or png.stat().st_size == 0:
        raise RuntimeError(f"Chromium wrote no screenshot (exit code {process.returncode}):\n{stderr}")
    return png


def _read_rgb(png_path: str | os.PathLike) -> np.ndarray:
    """Return the PNG's pixels as an (H, W, 3) int16 array of 0-255 values."""
    with Image.open(png_path) as image:
        return np.asarray(image.convert("RGB"), dtype=np.int16)


def count_colour_pixels(png_path: str | os.PathLike, rgb: tuple[int, int, int], tolerance: float) -> int:
    """Count pixels within Euclidean distance ``tolerance`` of the colour ``rgb``.

    Colours are 0-255 per channel.  Lit surfaces are shaded, so a flat-coloured
    object spans a range of colours; use a generous tolerance (about 60-100), or
    ``blue_pixel_fraction`` for blue objects.
    """
    pixels = _read_rgb(png_path)
    distance = np.linalg.norm(pixels - np.asarray(rgb, dtype=np.int16), axis=-1)
    return int(np.count_nonzero(distance <= tolerance))


def blue_pixel_fraction(png_path: str | os.PathLike) -> float:
    """Return the fraction of pixels that are distinctly blue.

    A pixel counts as blue when its blue channel exceeds red by more than 60 and
    green by more than 30.  This holds for every shade of a lit object coloured
    Rgba(0.2, 0.4, 0.9, 1), and not for Meshcat's grey background and grid.  The
    only blue in an empty Meshcat scene is the z axis of the world-frame triad,
    about 0.02 % of a 1280x800 screenshot.
    """
    pixels = _read_rgb(png_path)
    red, green, blue = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return float(np.mean((blue > red + 60) & (blue > green + 30)))
