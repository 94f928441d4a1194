"""The video's frames rendered by several processes (``write_video(jobs=...)``,
:mod:`sim.render.workers`).

Specification: whatever the number of processes, the encoder gets the same frames, bit for
bit, as one process renders (the oracle: the in-process path, ``jobs=1``, through the
``frame_sink`` hook), each frame index exactly once and in order. A worker that sends a frame
twice, leaves one out, sends one nobody asked for, fails or dies is caught with one line, and
then no video file, no partial file and no child process is left; so too after an interrupt.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest
from support import video_worker_faults as faults

import sim.render.gl as gl
import sim.render.workers as workers
from sim.cli import main
from sim.errors import RenderError
from sim.render.synthetic import write_synthetic_run
from sim.render.video import MIN_FRAMES_PER_JOB, resolve_jobs, write_video
from sim.render.workers import FrameJob, FramePool, render_record

pytestmark = pytest.mark.render

DURATION, FPS, W, H = 2.0, 10.0, 96, 72
N = int(DURATION * FPS) + 1  # frames


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    gl.configure_gl()
    return write_synthetic_run(tmp_path_factory.mktemp("workers") / "run", duration=DURATION)


def _children() -> set[int]:
    """This process's child processes, zombies included (from /proc)."""
    me, out = os.getpid(), set()
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        if int(stat.rsplit(")", 1)[1].split()[1]) == me:
            out.add(int(entry))
    return out


def _video(run_dir: Path, out: Path, jobs: int, cameras: tuple[str, ...] = ("overview",)
           ) -> tuple[int, list[tuple[int, np.ndarray]]]:
    """Writes the video with ``jobs`` processes; (processes used, frames the encoder got)."""
    got: list[tuple[int, np.ndarray]] = []
    result = write_video(run_dir, out, cameras=cameras, width=W, height=H, fps=FPS, jobs=jobs,
                         frame_sink=lambda k, frame: got.append((k, frame.copy())))
    assert result.frames == N and out.exists()
    return result.jobs, got


def test_two_processes_give_the_frames_of_one(run_dir: Path, tmp_path: Path) -> None:
    cameras = ("overview", "tool")  # two tiles side by side, captions drawn by the parent
    before = _children()
    jobs, serial = _video(run_dir, tmp_path / "one.mp4", 1, cameras)
    assert jobs == 1
    assert [k for k, _ in serial] == list(range(N))
    assert serial[0][1].shape == (H, 2 * W, 3)
    # the frames differ from each other: equal frames below mean equal rendering
    assert len({frame.tobytes() for _, frame in serial}) == N
    jobs, parallel = _video(run_dir, tmp_path / "two.mp4", 2, cameras)
    assert jobs == 2
    assert [k for k, _ in parallel] == list(range(N))  # each once, in order
    for (k, a), (_, b) in zip(serial, parallel, strict=True):
        assert np.array_equal(a, b), f"frame {k} differs between 1 and 2 processes"
    assert _children() <= before  # the workers are gone (and waited for)


def test_a_worker_gets_only_the_arrays_frames_read(run_dir: Path) -> None:
    from sim.simulation.runfolder import load_run

    record = load_run(run_dir)
    trimmed = render_record(record)
    assert set(trimmed.arrays) == set(record.arrays) & set(workers.RENDER_ARRAYS)
    assert "tau" in record.arrays and "tau" not in trimmed.arrays  # the caption's: parent only
    assert trimmed.model_path == record.model_path and record.arrays["tau"] is not None


SLOW = pytest.mark.slow  # a worker process each (1-2 s of CPU): the fast share keeps three


@pytest.mark.parametrize(("fault", "message"), [
    pytest.param(faults.duplicate, f"video worker 1 of 1 sent frame {faults.AT} twice",
                 id="duplicate"),
    pytest.param(faults.skip, f"video worker 1 of 1 skipped frame {faults.AT} (sent "
                 f"{faults.AT + 1} after it)", id="skip", marks=SLOW),
    pytest.param(faults.skip_last, "video worker 1 of 1 ended a chunk without frame 7",
                 id="skip_last"),
    pytest.param(faults.unasked, "video worker 1 of 1 sent frame 1007, which it was not asked "
                 "for", id="unasked", marks=SLOW),
    pytest.param(faults.fails, "video worker 1 of 1 failed: ValueError: planted failure at "
                 "frame 5", id="fails", marks=SLOW),
    pytest.param(faults.dies, "video worker 1 of 1 ended unexpectedly (exit code 7: planted "
                 "crash at frame 5)", id="dies"),
])
def test_a_worker_that_breaks_the_protocol_is_caught(run_dir: Path, fault: object,
                                                     message: str) -> None:
    from sim.simulation.runfolder import load_run

    record = load_run(run_dir)
    times = record.t0 + np.arange(N) / FPS
    job = FrameJob(record, times, ("overview",), W, H, gl.configure_gl())
    before = _children()
    delivered: list[int] = []
    with pytest.raises(RenderError) as info:
        with FramePool(job, 1, chunk_renderer=fault, chunk=4) as pool:  # type: ignore[arg-type]
            for k, frame in pool.frames():
                assert frame.shape == (H, W, 3)
                delivered.append(k)
    assert str(info.value) == message
    # in order, and nothing past the chunk after the fault's (frames 4-7 with chunks of 4)
    assert delivered == list(range(len(delivered))) and len(delivered) <= 8
    assert _children() <= before


def test_a_failing_worker_leaves_no_file_and_no_process(run_dir: Path, tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(workers, "render_chunk", faults.fails)  # what the workers are sent
    before = _children()
    out = tmp_path / "v.mp4"
    with pytest.raises(RenderError) as info:
        write_video(run_dir, out, width=W, height=H, fps=FPS, jobs=2)
    assert re.fullmatch(r"video worker [12] of 2 failed: ValueError: planted failure at "
                        r"frame 5", str(info.value))
    assert list(tmp_path.iterdir()) == []  # neither the video nor its partial file
    assert _children() <= before


def test_an_interrupt_leaves_no_file_and_no_process(run_dir: Path, tmp_path: Path) -> None:
    def interrupt(k: int, frame: np.ndarray) -> None:
        if k == 3:
            raise KeyboardInterrupt

    before = _children()
    with pytest.raises(KeyboardInterrupt):
        write_video(run_dir, tmp_path / "v.mp4", width=W, height=H, fps=FPS, jobs=2,
                    frame_sink=interrupt)
    assert list(tmp_path.iterdir()) == []
    assert _children() <= before


def test_an_unknown_camera_reads_the_same_with_workers(run_dir: Path, tmp_path: Path,
                                                       capsys: pytest.CaptureFixture) -> None:
    before = _children()
    assert main(["render", str(run_dir), "--camera", "top", "--width", "64", "--height", "48",
                 "--jobs", "2", "--out", str(tmp_path / "v.mp4"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "cellsim: error: unknown camera 'top'; the model's cameras: overview, tool"
    assert list(tmp_path.iterdir()) == []
    assert _children() <= before


def test_process_counts() -> None:
    cores = workers.usable_cores()
    assert resolve_jobs(None, MIN_FRAMES_PER_JOB - 1) == 1  # a short video: one process
    assert resolve_jobs(None, 10**5) == cores
    assert resolve_jobs(None, 2 * MIN_FRAMES_PER_JOB) == min(cores, 2)
    assert resolve_jobs(3, 2) == 2 and resolve_jobs(3, 100) == 3
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(RenderError, match="video jobs must be a positive whole number"):
            resolve_jobs(bad, 100)  # type: ignore[arg-type]
    # bounded: a trial's --video-jobs 1000 started 300 renderers and ran out of memory
    top = max(8, 4 * cores)
    assert resolve_jobs(top, 10**5) == top
    with pytest.raises(RenderError, match=f"at most {top} processes"):
        resolve_jobs(top + 1, 10**5)


def test_cli_refuses_a_bad_process_count(capsys: pytest.CaptureFixture) -> None:
    for argv in (["render", "somewhere", "--jobs", "0"],
                 ["run", "bugnar_5r_weld_cycle", "--video-jobs", "x"]):
        with pytest.raises(SystemExit) as info:
            main(argv)
        assert info.value.code == 2
    assert "expected at least 1 process, got 0" in capsys.readouterr().err
    # too many: refused before anything is simulated (one line, exit 2)
    assert main(["run", "bugnar_5r_phase1", "--video-jobs", "1000", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "video jobs: at most" in err and "got 1000" in err
