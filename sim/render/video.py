"""MP4 videos of recorded runs (H.264, yuv420p) with background encoding.

:func:`write_video` renders the run at the video's own frame times ``t0 + k / fps``,
``k = 0 .. floor(duration * fps)`` (so ``floor(duration * fps) + 1`` frames), interpolating
the recorded states between samples (it does not render every physics step). The frames are
rendered by ``jobs`` processes (default: one per usable core; :mod:`sim.render.workers`), each
with its own OpenGL context, or in this process with ``jobs=1``. They go, in order and as they
arrive, through a bounded queue to a background thread that draws the caption and feeds
imageio's ffmpeg writer (imageio-ffmpeg's static ffmpeg, libx264), so encoding overlaps
rendering. The file is written under a temporary name in the same folder and renamed when
complete; on error or interruption the partial file is removed (and the workers stopped).
"""

from __future__ import annotations

import os
import queue
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sim.errors import RenderError
from sim.render.overlay import OverlayStyle, caption_text, draw_caption
from sim.simulation.runfolder import RunRecord

#: ``frame_sink(index, frame)``: sees every frame as it goes to the encoder (caption drawn).
FrameSink = Callable[[int, np.ndarray], None]

#: Fewest frames per worker process when ``jobs`` is left to the default: a process costs
#: a second or two of CPU to start (interpreter, model, OpenGL context), a software frame
#: 0.02-0.2 s: a short video is rendered in one process.
MIN_FRAMES_PER_JOB = 64


@dataclass(frozen=True)
class VideoResult:
    """What :func:`write_video` wrote.

    Attributes:
        path: The MP4 file.
        frames: Number of frames, ``floor(duration * fps) + 1``.
        fps: Frames per second of the video.
        width: Frame width, pixels (tile width x number of cameras).
        height: Frame height, pixels.
        seconds: Wall-clock time of the whole call (model load, OpenGL context, ffmpeg start,
            rendering, encoding), s.
        loop_seconds: Wall-clock time from the first frame to the encoder's last, s.
        backend: OpenGL backend used.
        jobs: Processes that rendered the frames (1: this one).
    """

    path: Path
    frames: int
    fps: float
    width: int
    height: int
    seconds: float
    loop_seconds: float
    backend: str
    jobs: int = 1

    @property
    def frames_per_second(self) -> float:
        """Throughput of the whole call, frames per wall-clock second."""
        return self.frames / self.seconds if self.seconds > 0 else float("inf")

    @property
    def loop_frames_per_second(self) -> float:
        """Throughput of the render + encode loop (set-up excluded), frames per second."""
        return self.frames / self.loop_seconds if self.loop_seconds > 0 else float("inf")


class _Encoder:
    """Background thread appending frames to an imageio writer, fed by a bounded queue.

    Items are ``(index, frame, caption)``; a non-empty caption is drawn in this thread
    (Pillow), in parallel with the next frame's rendering (MuJoCo releases the GIL while
    rendering); ``sink`` then sees the frame.
    """

    _STOP = object()

    def __init__(self, writer: Any, maxsize: int, path: Path, log: Path | None = None,
                 sink: FrameSink | None = None) -> None:
        self.writer = writer
        self.path = path
        self.log = log
        self.sink = sink
        self.queue: queue.Queue[Any] = queue.Queue(maxsize=max(1, maxsize))
        self.error: BaseException | None = None
        self.sink_error: BaseException | None = None  # raised as itself, not as encoding's
        self.thread = threading.Thread(target=self._run, name="cellsim-video-encoder", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while True:
            item = self.queue.get()
            if item is self._STOP:
                return
            if self.error is not None:
                continue  # drain after a failure so put() never blocks forever
            try:
                index, frame, caption = item
                if caption:
                    draw_caption(frame, caption)
                if self.sink is not None:
                    try:
                        self.sink(index, frame)
                    except BaseException as exc:  # noqa: BLE001 - reported to the producer
                        self.sink_error = exc
                        raise
                self.writer.append_data(frame)
            except BaseException as exc:  # noqa: BLE001 - reported to the producer
                self.error = exc

    def _raise(self) -> None:
        if self.sink_error is not None:
            raise self.sink_error
        if self.error is not None:
            raise _encoding_error(self.error, self.path, self.log) from self.error

    def put(self, index: int, frame: np.ndarray, caption: str = "") -> None:
        self._raise()
        self.queue.put((index, frame, caption))

    def finish(self) -> None:
        self.queue.put(self._STOP)
        self.thread.join()
        self._raise()


#: x264's speed presets, fastest first.
PRESETS: tuple[str, ...] = ("ultrafast", "superfast", "veryfast", "faster", "fast", "medium",
                            "slow", "slower", "veryslow", "placebo")


@contextmanager
def _ffmpeg_log() -> Iterator[Path | None]:
    """ffmpeg runs with ``-v quiet`` (its lines would break the one-line rule on errors) and
    reports its errors to a temporary log instead (``FFREPORT``, read by the ffmpeg that the
    encoder thread starts); the log is removed afterwards. None when no log can be made."""
    try:
        fd, name = tempfile.mkstemp(prefix="cellsim-ffmpeg-", suffix=".log")
        os.close(fd)
    except OSError:
        yield None
        return
    log = Path(name)
    before = os.environ.get("FFREPORT")
    escaped = str(log).replace("\\", "\\\\").replace(":", "\\:")
    os.environ["FFREPORT"] = f"file={escaped}:level=16"
    try:
        yield log
    finally:
        if before is None:
            os.environ.pop("FFREPORT", None)
        else:
            os.environ["FFREPORT"] = before
        try:
            log.unlink()
        except OSError:
            pass


def _ffmpeg_said(log: Path | None) -> str:
    """The first error line ffmpeg logged ('' when none)."""
    if log is None:
        return ""
    try:
        lines = log.read_text(errors="replace").splitlines()
    except OSError:
        return ""
    said = [line.split("] ", 1)[-1].strip() for line in lines[2:] if line.strip()]
    return said[0] if said else ""


def _encoding_error(error: BaseException, path: Path, log: Path | None = None) -> Exception:
    """One line for an encoder failure: a probe write next to the partial file tells a full or
    read-only disk (an ``OSError`` with the path, reported like any other) from an encoder
    fault (a ``RenderError`` with ffmpeg's first error line, else what imageio said)."""
    probe = path.with_name(f".{path.stem}.probe")
    try:
        with open(probe, "wb") as fh:
            fh.write(b"\0" * (1 << 20))
            fh.flush()
            os.fsync(fh.fileno())
    except OSError as exc:
        return OSError(exc.errno, exc.strerror or str(exc), str(path))
    finally:
        try:
            probe.unlink()
        except OSError:
            pass
    first = _ffmpeg_said(log) or next(
        (line.strip() for line in str(error).splitlines() if line.strip()), type(error).__name__)
    return RenderError(f"video encoding of {path} failed: {first}")


def _partial_path(path: Path) -> Path:
    return path.with_name(f".{path.stem}.partial{path.suffix}")


def check_video_args(model: Any, video_args: Mapping[str, Any]) -> None:
    """Refuses bad video settings of a run (:func:`write_video`'s keyword arguments) before it
    is simulated: unknown cameras, a bad size, frame rate, playback speed or process count.

    Raises:
        RenderError: One line naming the setting.
    """
    from sim.render.frames import resolve_cameras, validate_size

    resolve_cameras(model, video_args.get("cameras", ("overview",)))
    validate_size(video_args.get("width", 640), video_args.get("height", 480))
    fps = video_args.get("fps", 30.0)
    if not (np.isfinite(fps) and fps > 0):
        raise RenderError(f"video fps (--fps): must be a positive number, got {fps!r}")
    speed = video_args.get("speed", 1.0)
    if not (np.isfinite(speed) and speed > 0):
        raise RenderError(f"video speed (--video-speed): must be a positive number, got "
                          f"{speed!r}")
    resolve_jobs(video_args.get("jobs"), 1)  # a bad process count


def max_jobs() -> int:
    """The most processes a video may be rendered by: 4 per usable core, at least 8 (more than
    the cores gain nothing; the bound keeps a mistyped count from exhausting the memory)."""
    from sim.render.workers import usable_cores

    return max(8, 4 * usable_cores())


def resolve_jobs(jobs: int | None, frames: int) -> int:
    """Processes that render ``frames`` frames: ``jobs`` (at most one per frame), or by default
    one per usable core and at most one per :data:`MIN_FRAMES_PER_JOB` frames.

    Raises:
        RenderError: ``jobs`` not a positive integer, or more than the usable cores (each
            process holds its own OpenGL context and scene, about 60 MB: a trial's 1000 ran
            the machine out of memory): more than :func:`max_jobs`.
    """
    from sim.render.workers import usable_cores

    cores = usable_cores()
    if jobs is None:
        return max(1, min(cores, frames // MIN_FRAMES_PER_JOB))
    if isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1:
        raise RenderError(f"video jobs must be a positive whole number of processes, got "
                          f"{jobs!r}")
    if jobs > max_jobs():
        raise RenderError(f"video jobs: at most {max_jobs()} processes (4 per core this process "
                          f"may use, {cores}; each renders with its own OpenGL context, about "
                          f"60 MB), got {jobs}")
    return max(1, min(int(jobs), frames))


@contextmanager
def _frame_source(record: RunRecord, times: np.ndarray, jobs: int, backend: str,
                  **render: Any) -> Iterator[Iterator[tuple[int, np.ndarray]]]:
    """``(index, frame)`` in order, without caption: rendered here (``jobs == 1``: one
    renderer, closed on leaving) or by worker processes (stopped on leaving)."""
    if jobs == 1:
        from sim.render.frames import FrameRenderer

        with FrameRenderer(record, caption=False, gl=backend, **render) as frames:
            yield ((k, frames.render(float(t), caption=False)) for k, t in enumerate(times))
        return
    from sim.render.workers import FrameJob, FramePool

    job = FrameJob(record=record, times=times, gl=backend, cameras=tuple(render["cameras"]),
                   width=render["width"], height=render["height"], overlay=render["overlay"],
                   style=render["style"])
    with FramePool(job, jobs) as pool:
        yield pool.frames()


def write_video(
    run: str | Path | RunRecord,
    path: str | Path,
    *,
    cameras: Sequence[str] = ("overview",),
    width: int = 640,
    height: int = 480,
    fps: float = 30.0,
    speed: float = 1.0,
    gl: str | None = None,
    progress: bool = False,
    overlay: bool = True,
    caption: bool = True,
    style: OverlayStyle | None = None,
    crf: int = 20,
    preset: str = "veryfast",
    queue_size: int = 8,
    jobs: int | None = None,
    frame_sink: FrameSink | None = None,
) -> VideoResult:
    """Renders a recorded run into an H.264 MP4.

    Args:
        run: A run folder (``model.xml`` + ``summary.json`` + ``trajectory.npz``) or a
            :class:`~sim.simulation.runfolder.RunRecord`.
        path: Output file; must end in ``.mp4``; parent folders are created.
        cameras: Camera names of the model, tiled left to right.
        width: Width of one camera tile, pixels (even, 16..8192).
        height: Height, pixels (even, 16..8192).
        fps: Frames per second (> 0).
        speed: Playback speed, simulated seconds per second of video (> 0; 4: a time-lapse
            four times faster than real time).
        gl: OpenGL backend ``"egl"`` / ``"osmesa"``, or None for automatic.
        progress: Show a progress bar on stderr (only when stderr is a terminal).
        overlay: Draw the tool-point trails and the weld bead.
        caption: Draw the caption (time, phase, highest joint torque).
        style: Overlay colours and sizes.
        crf: x264 constant rate factor (0 lossless .. 51 worst; 18-23 looks good).
        preset: x264 speed preset (``ultrafast`` .. ``veryslow``).
        queue_size: Frames buffered between renderer and encoder.
        jobs: Processes rendering frames, each with its own OpenGL context (1: this process
            alone); None: one per usable core, at most one per :data:`MIN_FRAMES_PER_JOB`
            frames. The frames are the same whatever the number.
        frame_sink: Called as ``frame_sink(index, frame)`` with every frame, in order, as it
            goes to the encoder (caption drawn); the frame must not be kept without a copy.

    Returns:
        A :class:`VideoResult`.

    Raises:
        RenderError: Bad path/size/fps/camera/jobs, no OpenGL backend, a worker process that
            failed, or the encoder failed.
        RunFolderError: The run folder is missing or malformed.
    """
    import imageio.v2 as imageio
    from tqdm import tqdm

    from sim.render.frames import frame_times, validate_size
    from sim.render.gl import configure_gl
    from sim.simulation.runfolder import REQUIRED_FOR_VIDEO, as_record

    out_path = Path(path)
    if out_path.suffix.lower() != ".mp4":
        raise RenderError(f"video file {str(out_path)!r} must end in .mp4 (H.264 MP4)")
    if not (isinstance(crf, int) and 0 <= crf <= 51):
        raise RenderError(f"crf must be an integer in 0..51, got {crf!r}")
    if preset not in PRESETS:
        raise RenderError(f"unknown x264 preset {preset!r}; valid: {', '.join(PRESETS)}")
    started = time.perf_counter()
    validate_size(width, height)
    record = as_record(run)
    record.require(REQUIRED_FOR_VIDEO)
    backend = configure_gl(gl)
    times = frame_times(record, fps, speed)
    n_jobs = resolve_jobs(jobs, len(times))
    cams = [str(cameras)] if isinstance(cameras, str) else [str(c) for c in cameras]
    render = {"cameras": cams, "width": width, "height": height, "overlay": overlay,
              "style": style}
    with _frame_source(record, times, n_jobs, backend, **render) as frames:
        out_path.parent.mkdir(parents=True, exist_ok=True)
        tmp = _partial_path(out_path)
        ok = False
        try:
            with _ffmpeg_log() as log:
                writer = imageio.get_writer(
                    tmp, format="FFMPEG", mode="I", fps=float(fps), codec="libx264",
                    pixelformat="yuv420p", quality=None, macro_block_size=2,
                    ffmpeg_log_level="quiet",
                    output_params=["-crf", str(crf), "-preset", preset,
                                   "-movflags", "+faststart"],
                )
                loop_start = time.perf_counter()
                try:
                    encoder = _Encoder(writer, queue_size, out_path, log, frame_sink)
                    bar = tqdm(total=len(times), unit="frame", desc="render", file=sys.stderr,
                               disable=not (progress and sys.stderr.isatty()), leave=False,
                               delay=1.0)  # only renders longer than a second show a bar
                    try:
                        for k, frame in frames:
                            text = caption_text(record, float(times[k])) if caption else ""
                            encoder.put(k, frame, text)
                            bar.update(1)
                    finally:
                        bar.close()
                        encoder.finish()
                except BaseException:
                    try:
                        writer.close()
                    except Exception:  # noqa: BLE001 - keep the first error
                        pass
                    raise
                try:
                    writer.close()  # waits for ffmpeg to encode the last frames
                except Exception as exc:  # noqa: BLE001 - the trailer could not be written
                    raise _encoding_error(exc, out_path, log) from exc
            loop_seconds = time.perf_counter() - loop_start
            os.replace(tmp, out_path)
            ok = True
        finally:
            if not ok and tmp.exists():
                tmp.unlink()
    return VideoResult(
        path=out_path, frames=len(times), fps=float(fps), width=width * len(cams), height=height,
        seconds=time.perf_counter() - started, loop_seconds=loop_seconds, backend=backend,
        jobs=n_jobs,
    )
