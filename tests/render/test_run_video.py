"""`cellsim run` with its video, on a real shipped scenario, with each available backend
(issue 6 acceptance): frame count, non-blank and changing frames, the trail in the last
frame, a clean interpreter exit."""

from __future__ import annotations

import json
import sys

import imageio.v3 as iio
import numpy as np
import pytest
from support.limits import run_limited

from sim.render import gl

AVAILABLE = gl.available_backends()
pytestmark = pytest.mark.render
FPS, W, H = 20.0, 160, 120


def _red(img: np.ndarray) -> np.ndarray:
    im = img.astype(int)
    r, g, b = im[..., 0], im[..., 1], im[..., 2]
    return (r - np.maximum(g, b) > 60) & (np.abs(g - b) < 60)


def test_some_backend_works():
    assert AVAILABLE


#: the fast share's ten minutes (issue 29): the first working backend there, the others slow
@pytest.mark.parametrize("backend", [b if i == 0 else pytest.param(b, marks=pytest.mark.slow)
                                     for i, b in enumerate(AVAILABLE)])
def test_cellsim_run_writes_video(backend, tmp_path):
    out = tmp_path / "run"
    res = run_limited(
        [sys.executable, "-m", "sim", "run", "kacso_lrmate100ib_sequence1", "--out", str(out),
         "--gl", backend, "--width", str(W), "--height", str(H), "--fps", str(FPS),
         "--camera", "overview", "--quiet"],
        capture_output=True, text=True, cpu_s=600)
    assert res.returncode == 0, res.stderr
    assert "Exception ignored" not in res.stderr and "Traceback" not in res.stderr, res.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["video"] == "video.mp4"
    frames = iio.imread(out / "video.mp4")
    expected = int(np.floor(summary["duration_s"] * FPS)) + 1
    assert abs(len(frames) - expected) <= 1
    assert frames.shape[1:] == (H, W, 3)
    assert all(f.std() > 10 for f in frames), "blank frame"
    diffs = [np.abs(frames[k + 1].astype(int) - frames[k].astype(int)).mean()
             for k in range(len(frames) - 1)]
    assert min(diffs) > 0.05, "consecutive frames identical"
    assert _red(frames[-1]).sum() > 5, "no actual-path trail in the last frame"
    assert (out / "report.html").read_text().count("video.mp4") >= 1
    assert len(list((out / "plots").glob("*.png"))) >= 4


def test_unknown_camera_refused_before_simulating(tmp_path):
    out = tmp_path / "run"
    res = run_limited(
        [sys.executable, "-m", "sim", "run", "kacso_lrmate100ib_sequence1", "--out", str(out),
         "--camera", "front", "--quiet"], capture_output=True, text=True, cpu_s=600)
    assert res.returncode == 2
    assert res.stderr.strip() == ("cellsim: error: unknown camera 'front'; the model's cameras: "
                                  "overview, tool")
    assert not out.exists() and not out.with_name("run.failed").exists()
