"""Video pipeline throughput against raw ``mujoco.Renderer.render()`` at the same size.

For each size (default 320x240, 640x480, 1280x720) it measures, on one camera:

* ``raw``: ``Renderer.update_scene(data, camera)`` + ``Renderer.render()`` per frame, states
  set beforehand (no overlay, no caption, no encoding): what MuJoCo alone can render;
* ``pipeline``: :func:`sim.render.video.write_video` (interpolated states, kinematics, trails and
  bead, caption, H.264 encoding in the background thread), frames / time of its frame loop
  (first frame to the encoder's last; ``e2e`` adds model load, OpenGL context, ffmpeg start);
* ``serial``: the same frames rendered and then encoded in one thread (what the background
  thread saves);
* ``no-ovl``: the pipeline without trails, bead and caption.

The target is ``pipeline >= 0.8 x raw``. Runs unchanged on a GPU machine (EGL) and on a CPU
(EGL on Mesa, or OSMesa). Without ``--run`` it renders the synthetic demo cell of
:mod:`sim.render.synthetic`.

Usage::

    python benchmarks/bench_video.py [--run RUN_DIR] [--camera overview] [--frames 90]
        [--sizes 320x240,640x480,1280x720] [--gl egl|osmesa] [--repeat N] [--json OUT.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sim.render.gl import configure_gl  # noqa: E402  (before anything imports mujoco)


def _sizes(text: str) -> list[tuple[int, int]]:
    out = []
    for item in text.split(","):
        w, h = item.lower().split("x")
        out.append((int(w), int(h)))
    return out


def bench_raw(record, camera: str, width: int, height: int,
              times: np.ndarray) -> tuple[float, str]:
    """Frames per second of update_scene + render alone, and the OpenGL renderer's name."""
    import mujoco

    from sim.render.interp import QposInterpolator

    model = record.load_model()
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    interp = QposInterpolator(model, record.t, record.get("qpos"))
    states = []
    for t in times:
        d = mujoco.MjData(model)
        d.qpos[:] = interp(float(t))
        mujoco.mj_forward(model, d)
        states.append(d)
    with mujoco.Renderer(model, height, width) as renderer:
        for d in states[:3]:  # warm-up (shader compilation, first allocations)
            renderer.update_scene(d, camera)
            renderer.render()
        try:
            from OpenGL import GL

            name = GL.glGetString(GL.GL_RENDERER).decode()
        except Exception:  # noqa: BLE001 - the name is informative only
            name = "?"
        start = time.perf_counter()
        for d in states:
            renderer.update_scene(d, camera)
            renderer.render()
        return len(states) / (time.perf_counter() - start), name


def bench_serial(record, camera: str, width: int, height: int, fps: float, path: Path) -> float:
    """Frames per second when rendering and encoding alternate in one thread."""
    import imageio.v2 as imageio

    from sim.render.frames import FrameRenderer

    with FrameRenderer(record, cameras=(camera,), width=width, height=height) as fr:
        times = fr.frame_times(fps)
        fr.render(float(times[0]))  # warm-up
        writer = imageio.get_writer(
            path, format="FFMPEG", mode="I", fps=fps, codec="libx264", pixelformat="yuv420p",
            quality=None, macro_block_size=2, ffmpeg_log_level="error",
            output_params=["-crf", "20", "-preset", "veryfast"],
        )
        start = time.perf_counter()
        try:
            for t in times:
                writer.append_data(fr.render(float(t)))
        finally:
            writer.close()
        return len(times) / (time.perf_counter() - start)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--run", type=Path, default=None, help="run folder (default: synthetic)")
    parser.add_argument("--camera", default="overview")
    parser.add_argument("--frames", type=int, default=90, help="frames per measurement")
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument("--sizes", type=_sizes, default=_sizes("320x240,640x480,1280x720"))
    parser.add_argument("--gl", choices=("egl", "osmesa"), default=None)
    parser.add_argument("--repeat", type=int, default=1,
                        help="measure each variant N times, interleaved, keep the best (noisy hosts)")
    parser.add_argument("--json", type=Path, default=None, help="also write the results here")
    args = parser.parse_args(argv)

    backend = configure_gl(args.gl)
    import mujoco

    from sim.render.synthetic import write_synthetic_run
    from sim.render.video import write_video
    from sim.simulation.runfolder import load_run

    with tempfile.TemporaryDirectory(prefix="bench_video_") as tmp_name:
        tmp = Path(tmp_name)
        if args.run is None:
            duration = (args.frames - 1) / args.fps + 0.01  # samples end at a multiple of 10 ms
            run_dir = write_synthetic_run(tmp / "run", duration=duration)
        else:
            run_dir = args.run
        record = load_run(run_dir)
        n_frames = int(np.floor(record.duration * args.fps + 1e-9)) + 1
        times = record.t0 + np.arange(n_frames) / args.fps
        print(f"# backend={backend} mujoco={mujoco.__version__} python={platform.python_version()} "
              f"machine={platform.machine()} frames={len(times)} camera={args.camera}")
        header = (f"{'size':>10} {'raw fps':>9} {'pipeline':>9} {'ratio':>6} {'e2e':>7} "
                  f"{'serial':>7} {'no-ovl':>7}")
        results = []
        for width, height in args.sizes:
            best: dict[str, float] = {}

            def keep(key: str, value: float) -> None:
                best[key] = max(best.get(key, 0.0), value)

            for _ in range(max(1, args.repeat)):
                raw, gl_name = bench_raw(record, args.camera, width, height, times)
                keep("raw", raw)
                res = write_video(record, tmp / f"p_{width}.mp4", cameras=(args.camera,),
                                  width=width, height=height, fps=args.fps)
                keep("pipeline", res.loop_frames_per_second)
                keep("e2e", res.frames_per_second)
                bare = write_video(record, tmp / f"b_{width}.mp4", cameras=(args.camera,),
                                   width=width, height=height, fps=args.fps, overlay=False,
                                   caption=False)
                keep("bare", bare.loop_frames_per_second)
                keep("serial", bench_serial(record, args.camera, width, height, args.fps,
                                            tmp / f"s_{width}.mp4"))
            if not results:
                print(f"# OpenGL renderer: {gl_name}")
                print(header)
            row = {
                "width": width, "height": height, "frames": len(times), "gl_renderer": gl_name,
                "raw_fps": best["raw"], "pipeline_fps": best["pipeline"],
                "ratio": best["pipeline"] / best["raw"], "end_to_end_fps": best["e2e"],
                "serial_fps": best["serial"], "no_overlay_fps": best["bare"],
                "no_overlay_ratio": best["bare"] / best["raw"],
            }
            results.append(row)
            print(f"{width:>5}x{height:<4} {row['raw_fps']:9.1f} {row['pipeline_fps']:9.1f} "
                  f"{row['ratio']:6.2f} {row['end_to_end_fps']:7.1f} {row['serial_fps']:7.1f} "
                  f"{row['no_overlay_fps']:7.1f}", flush=True)
    if args.json:
        args.json.write_text(json.dumps({"backend": backend, "results": results}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
