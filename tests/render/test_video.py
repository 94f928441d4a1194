"""MP4 videos of recorded runs and ``cellsim render``.

Each available OpenGL backend (probed; EGL works on this machine's Mesa, OSMesa only when
libOSMesa is installed) renders a short synthetic run in a fresh interpreter, which also
checks that the interpreter exits cleanly (no "Exception ignored" from unfreed renderers).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from support.limits import run_limited

import sim.render.gl as gl
from sim.cli import main
from sim.errors import RenderError
from sim.render.synthetic import write_synthetic_run

REPO = Path(__file__).resolve().parents[2]
AVAILABLE = gl.available_backends()
pytestmark = pytest.mark.render

DURATION, FPS, WIDTH, HEIGHT = 2.0, 10.0, 160, 120


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    gl.configure_gl()
    return write_synthetic_run(tmp_path_factory.mktemp("video") / "run", duration=DURATION)


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _red(img: np.ndarray) -> np.ndarray:
    """Pixels of the actual-path red after H.264 (chroma is subsampled: loose bounds)."""
    im = img.astype(int)
    r, g, b = im[..., 0], im[..., 1], im[..., 2]
    return (r - np.maximum(g, b) > 60) & (np.abs(g - b) < 60)


def test_a_backend_is_available() -> None:
    assert AVAILABLE, "no OpenGL backend works; EGL on Mesa is expected to work here"


@pytest.mark.parametrize("backend", AVAILABLE)
def test_video_with_each_available_backend(backend: str, run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / f"{backend}.mp4"
    code = (
        "import sys\n"
        "from sim.render.video import write_video\n"
        f"r = write_video(sys.argv[1], sys.argv[2], width={WIDTH}, height={HEIGHT}, fps={FPS},"
        f" gl={backend!r})\n"
        "print(r.frames, r.backend)\n"
    )
    proc = run_limited([sys.executable, "-c", code, str(run_dir), str(out)], env=_env(),
                          capture_output=True, text=True, cpu_s=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "Exception ignored" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stdout.split() == [str(int(DURATION * FPS) + 1), backend]

    frames = iio.imread(out)
    meta = iio.immeta(out)
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
    assert meta["fps"] == pytest.approx(FPS)
    assert abs(len(frames) - DURATION * FPS) <= 1
    assert frames.shape[1:] == (HEIGHT, WIDTH, 3)
    for k, frame in enumerate(frames):
        assert frame.std() > 15.0, f"frame {k} is blank"
    for k in range(len(frames) - 1):
        diff = np.abs(frames[k + 1].astype(int) - frames[k].astype(int)).mean()
        assert diff > 0.1, f"frames {k} and {k + 1} are identical"
    assert _red(frames[-1]).sum() > 20, "the actual-path trail colour is missing in the last frame"
    assert _red(frames[0]).sum() < 5  # nothing travelled at t = 0
    text = frames[0][: HEIGHT // 10].min(axis=2) > 180  # white caption text on the dark strip
    assert text.sum() > 10


def test_clean_exit_after_an_error_inside_the_render_loop(run_dir: Path, tmp_path: Path) -> None:
    """A failure mid-video (the encoder fails at its fourth frame) closes everything, leaves no
    file, and says what failed in one line."""
    code = (
        "import sys\n"
        "import imageio.v2 as imageio\n"
        "real = imageio.get_writer\n"
        "class Failing:\n"
        "    def __init__(self, *a, **k):\n"
        "        self.w, self.n = real(*a, **k), 0\n"
        "    def append_data(self, frame):\n"
        "        self.n += 1\n"
        "        if self.n == 4:\n"
        "            raise RuntimeError('encoder says no')\n"
        "        self.w.append_data(frame)\n"
        "    def close(self):\n"
        "        self.w.close()\n"
        "imageio.get_writer = Failing\n"
        "from sim.render.video import write_video\n"
        "from sim.errors import RenderError\n"
        "try:\n"
        "    write_video(sys.argv[1], sys.argv[2], width=64, height=48, fps=5)\n"
        "except RenderError as exc:\n"
        "    print('RenderError', exc)\n"
    )
    out = tmp_path / "bad.mp4"
    proc = run_limited([sys.executable, "-c", code, str(run_dir), str(out)], env=_env(),
                          capture_output=True, text=True, cpu_s=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == f"RenderError video encoding of {out} failed: encoder says no\n"
    assert proc.stderr == ""  # ffmpeg is quiet; nothing ignored at exit
    assert list(tmp_path.iterdir()) == []  # neither the video nor its partial file


def test_an_unknown_preset_lists_the_valid_ones(run_dir: Path, tmp_path: Path) -> None:
    from sim.render.video import PRESETS, write_video

    with pytest.raises(RenderError, match="unknown x264 preset 'nosuch'; valid: ultrafast, "):
        write_video(run_dir, tmp_path / "x.mp4", width=64, height=48, fps=5, preset="nosuch")
    assert "veryfast" in PRESETS and list(tmp_path.iterdir()) == []


def test_ffmpeg_errors_reach_the_message_through_its_log(tmp_path: Path) -> None:
    """ffmpeg runs with -v quiet; what it reports goes to a temporary log (FFREPORT) whose first
    error line is what the user reads; the log is removed afterwards."""
    import imageio_ffmpeg

    from sim.render.video import _ffmpeg_log, _ffmpeg_said

    target = tmp_path / "missing" / "x.mp4"
    before = os.environ.get("FFREPORT")
    with _ffmpeg_log() as log:
        assert log is not None and log.is_file()
        proc = run_limited([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "quiet", "-f", "lavfi",
                               "-i", "color=size=16x16:duration=0.1", str(target)],
                              capture_output=True, text=True, cpu_s=60)
        said = _ffmpeg_said(log)
    assert proc.returncode != 0 and proc.stderr == ""
    assert str(target) in said and "No such file or directory" in said
    assert not log.exists() and os.environ.get("FFREPORT") == before


def test_tiled_video_and_result(run_dir: Path, tmp_path: Path) -> None:
    from sim.render.video import write_video

    result = write_video(run_dir, tmp_path / "sub" / "two.mp4", cameras=("overview", "tool"),
                         width=64, height=48, fps=4.0)
    assert result.path.is_file() and result.frames == 9
    assert (result.width, result.height) == (128, 48)
    assert result.backend == gl.active_backend()
    frames = iio.imread(result.path)
    assert frames.shape == (9, 48, 128, 3)
    assert [p.name for p in (tmp_path / "sub").iterdir()] == ["two.mp4"]


def test_video_argument_errors(run_dir: Path, tmp_path: Path) -> None:
    from sim.render.video import write_video

    with pytest.raises(RenderError, match=r"must end in \.mp4"):
        write_video(run_dir, tmp_path / "v.avi")
    message = "unknown camera 'side'; the model's cameras: overview, tool"
    with pytest.raises(RenderError, match=message):
        write_video(run_dir, tmp_path / "v.mp4", cameras=("side",), width=64, height=48)
    with pytest.raises(RenderError, match="fps must be a positive"):
        write_video(run_dir, tmp_path / "v.mp4", width=64, height=48, fps=0)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------ cellsim render


def test_cli_render_missing_folder_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["render", str(tmp_path / "missing")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert err.startswith("cellsim: error: run folder") and "does not exist" in err


def test_cli_render_unknown_camera_exits_2(run_dir: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["render", str(run_dir), "--camera", "top", "--width", "64", "--height", "48",
                 "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "cellsim: error: unknown camera 'top'; the model's cameras: overview, tool"


def test_cli_render_odd_width_exits_2(run_dir: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["render", str(run_dir), "--width", "161", "--quiet"]) == 2
    assert "width must be even" in capsys.readouterr().err


def test_cli_render_writes_video(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "cli.mp4"
    proc = run_limited(
        [sys.executable, "-m", "sim", "render", str(run_dir), "--out", str(out), "--width", "80",
         "--height", "60", "--fps", "5", "--camera", "tool", "--quiet"],
        env=_env(), capture_output=True, text=True, cpu_s=300, check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ""  # --quiet
    assert "Exception ignored" not in proc.stderr and "render:" not in proc.stderr  # no bar
    frames = iio.imread(out)
    assert frames.shape == (11, 60, 80, 3)
