"""``cellsim render RUN_DIR``: re-render a finished run into an MP4 (and plots) without simulating.

Reads ``RUN_DIR/model.xml`` and ``RUN_DIR/trajectory.npz`` (see :mod:`sim.simulation.runfolder`),
renders the recorded states at the video's frame times with the tool-point trails, weld bead
and caption, and writes ``RUN_DIR/video.mp4`` (or ``--out``). ``--plots`` also writes the
PNG plots into ``RUN_DIR/plots/``. The OpenGL backend is chosen before mujoco is imported
(``--gl`` forces one). The frames are rendered by one process per core (``--jobs``), each
with its own OpenGL context, and encoded in order as they arrive. A progress bar is shown on
long renders when stderr is a terminal; ``--quiet`` hides it and the summary line.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from sim.errors import RenderError
from sim.simulation.runfolder import VIDEO_MP4, note_written, written_by_cellsim


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a whole number of pixels, got {text!r}"
        ) from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number of pixels, got {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text}")
    return value


def fps_arg(text: str) -> float:
    """``--fps``: a frame rate in :data:`~sim.core.tomlschema.FPS`'s range."""
    from sim.core.tomlschema import FPS

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    bad = FPS.problem(value)
    if bad:
        raise argparse.ArgumentTypeError(bad)
    return value


def _jobs(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a whole number of processes, got {text!r}"
        ) from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected at least 1 process, got {value}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "render",
        help="re-render a finished run (RUN_DIR) into an MP4 video, without simulating",
        description="Render the recorded states of a finished run (RUN_DIR/model.xml and "
                    "RUN_DIR/trajectory.npz) into an H.264 MP4: tool-point reference path "
                    "(green), actual path (red), weld bead (gold), caption with time, phase "
                    "and the highest joint torque. Several --camera views are tiled side by side.",
    )
    p.add_argument("run_dir", metavar="RUN_DIR", help="folder written by `cellsim run`")
    p.add_argument("--out", metavar="FILE", default=None,
                   help="output .mp4 (default: RUN_DIR/video.mp4)")
    p.add_argument("--gl", choices=("egl", "osmesa"), default=None,
                   help="OpenGL backend (default: EGL if it works, else OSMesa)")
    p.add_argument("--width", type=_positive_int, default=640,
                   help="width of each camera view, pixels, even (default 640)")
    p.add_argument("--height", type=_positive_int, default=480,
                   help="height, pixels, even (default 480)")
    p.add_argument("--fps", type=fps_arg, default=30.0,
                   help="frames per second (default 30); frames = floor(duration*fps/speed)+1")
    p.add_argument("--speed", type=_positive_float, default=1.0,
                   help="playback speed, simulated seconds per second of video (default 1; "
                        "4: a time-lapse four times faster than real time)")
    p.add_argument("--camera", action="append", metavar="NAME", dest="cameras", default=None,
                   help="camera of the cell to render (repeatable; default: overview)")
    p.add_argument("--jobs", type=_jobs, metavar="N", default=None,
                   help="processes rendering frames, each with its own OpenGL context "
                        "(default: one per core; 1: in this process)")
    p.add_argument("--plots", action="store_true",
                   help="also write the PNG plots into RUN_DIR/plots/")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no summary line")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sim.render.gl import configure_gl
    from sim.simulation.runfolder import load_run

    record = load_run(args.run_dir)  # one-line error (exit 2) for a missing/invalid folder
    backend = configure_gl(args.gl)  # before anything imports mujoco
    from sim.render.video import write_video

    out = Path(args.out) if args.out else Path(args.run_dir) / VIDEO_MP4
    if out.suffix.lower() != ".mp4":
        raise RenderError(f"--out {str(out)!r} must end in .mp4")
    if not out.parent.is_dir():
        raise RenderError(f"--out {str(out)!r}: no such folder {str(out.parent)!r}")
    if (out.exists() or out.is_symlink()) and not written_by_cellsim(out, args.run_dir):
        raise RenderError(f"{out}: exists; cellsim does not overwrite files it did not write "
                          "(remove it or choose another --out)")
    if args.plots:  # refused before the video is rendered, not after
        from sim.analysis.plots import check_plots_dir
        from sim.simulation.runfolder import PLOTS_DIR

        check_plots_dir(Path(args.run_dir) / PLOTS_DIR)
    result = write_video(
        record, out, cameras=tuple(args.cameras or ("overview",)), width=args.width,
        height=args.height, fps=args.fps, speed=args.speed, gl=backend, progress=not args.quiet, jobs=args.jobs,
    )
    if not args.quiet:
        print(
            f"wrote {result.path} ({result.frames} frames, {result.width}x{result.height}, "
            f"{result.fps:g} fps, {result.seconds:.1f} s, {result.frames_per_second:.1f} "
            f"frames/s, {result.jobs} process{'es' if result.jobs > 1 else ''}, OpenGL "
            f"{result.backend})"
        )
    written = [out]
    if args.plots:
        from sim.analysis.plots import write_plots

        paths = write_plots(record)
        written += list(paths)
        if not args.quiet:
            print(f"wrote {len(paths)} plots into {paths[0].parent}")
    note_written(args.run_dir, written)  # a later run into the folder may replace them
    return 0
