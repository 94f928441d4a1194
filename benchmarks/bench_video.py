"""Video pipeline throughput with 1 and N processes against one process's raw
``mujoco.Renderer.render()`` at the same size.

For each size (default 480x360, the default weld cycle's video) it measures, on one camera:

* ``raw``: one process, ``Renderer.update_scene(data, camera)`` + ``Renderer.render()`` per
  frame, each state set outside the timed part (no overlay, no caption, no encoding): what
  MuJoCo alone renders in one process, of the pipeline's own scene (the renderer a
  :class:`~sim.render.frames.FrameRenderer` opens: the same framed camera and field of view,
  framebuffer at the tile's size, shadow map sized by :func:`~sim.render.frames.shadow_size`,
  the model's multisampling; the settings are printed). Measured in a fresh interpreter
  twice: with the environment's ``LP_NUM_THREADS`` (Mesa llvmpipe's default is one rasterizer
  thread per core, so one process already uses more than one core) and with
  ``LP_NUM_THREADS=1`` (``raw1``: one process on one core);
* ``pipe 1`` / ``pipe N``: :func:`sim.render.video.write_video` with ``jobs=1`` (one process,
  llvmpipe's threads as configured) and ``jobs=N`` (N worker processes, default one per usable
  core; each with ``LP_NUM_THREADS=1`` unless set): interpolated states, kinematics, trails
  and bead, caption, H.264 encoding; frames per second of the whole call (``e2e``: worker
  start-up, model load, OpenGL context, ffmpeg start included) and of its frame loop.

It prints the ratio of the N-process pipeline's frames per second (whole call) to ``raw`` and
to ``raw1`` (target >= 1.7 with 2 processes against one process), each variant's CPU time per
frame (its process and children), and the load average before and after: on a shared machine
wall-clock rates depend on the load, CPU times much less. ``--lp-threads K`` runs the
N-process pipeline with ``LP_NUM_THREADS=K`` in its workers instead (e.g. 2: llvmpipe's
default on 2 cores). Runs unchanged on a GPU machine (EGL) and on a CPU (EGL on Mesa, or
OSMesa). Without ``--run`` it renders the synthetic demo cell of :mod:`sim.render.synthetic`.

Usage::

    python benchmarks/bench_video.py [--run RUN_DIR] [--camera overview] [--frames 120]
        [--sizes 480x360,...] [--jobs N] [--lp-threads K] [--gl egl|osmesa] [--repeat N]
        [--json OUT.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sim.render.gl import configure_gl  # noqa: E402  (before anything imports mujoco)

_RAW = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1])
from sim.render.gl import adopt_backend
adopt_backend(sys.argv[2])
import numpy as np
from sim.render.frames import FrameRenderer
from sim.simulation.runfolder import load_run
record = load_run(sys.argv[3])
camera, fps, n = sys.argv[4], float(sys.argv[7]), int(sys.argv[8])
width, height = int(sys.argv[5]), int(sys.argv[6])
# the pipeline's own scene: its framebuffer and shadow map sizes, framed camera and field of
# view, multisampling as the model has it; no overlay, no caption, no encoding
with FrameRenderer(record, cameras=(camera,), width=width, height=height, overlay=False,
                   caption=False, gl=sys.argv[2]) as frames:
    renderer = frames._renderer
    times = record.t0 + np.arange(n) / fps
    for t in times[:3]:  # warm-up (shader compilation, first allocations)
        frames.set_state(float(t))
        frames._update_scene(0)
        renderer.render()
    try:
        from OpenGL import GL
        name = GL.glGetString(GL.GL_RENDERER).decode()
    except Exception:
        name = "?"
    wall = cpu = 0.0
    for t in times:
        frames.set_state(float(t))  # the state is set outside the timed part
        w0, c0 = time.perf_counter(), time.process_time()
        frames._update_scene(0)  # Renderer.update_scene(data, the framed camera)
        renderer.render()
        wall += time.perf_counter() - w0
        cpu += time.process_time() - c0
    settings = {"shadowsize": int(frames.model.vis.quality.shadowsize),
                "offsamples": int(frames.model.vis.quality.offsamples),
                "offwidth": int(frames.model.vis.global_.offwidth),
                "offheight": int(frames.model.vis.global_.offheight)}
print(json.dumps({"fps": len(times) / wall, "cpu_ms": 1000 * cpu / len(times), "gl": name,
                  "settings": settings}))
"""


def _sizes(text: str) -> list[tuple[int, int]]:
    out = []
    for item in text.split(","):
        w, h = item.lower().split("x")
        out.append((int(w), int(h)))
    return out


def _cpu() -> float:
    """CPU seconds of this process and its waited-for children."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def bench_raw(run_dir: Path, backend: str, camera: str, width: int, height: int, fps: float,
              frames: int, lp_threads: str | None) -> dict:
    """Raw render rate of one fresh process (``lp_threads``: its LP_NUM_THREADS, None: as the
    environment has it)."""
    env = dict(os.environ)
    if lp_threads is not None:
        env["LP_NUM_THREADS"] = lp_threads
    root = str(Path(__file__).resolve().parents[1])
    proc = subprocess.run(
        [sys.executable, "-c", _RAW, root, backend, str(run_dir), camera, str(width),
         str(height), str(fps), str(frames)], env=env, capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def bench_pipeline(record, path: Path, camera: str, width: int, height: int, fps: float,
                   jobs: int, lp_threads: str | None) -> dict:
    """write_video with ``jobs`` processes: frames/s of the call and of its loop, CPU/frame."""
    from sim.render.video import write_video

    before = os.environ.get("LP_NUM_THREADS")
    if lp_threads is not None:  # the workers inherit it
        os.environ["LP_NUM_THREADS"] = lp_threads
    try:
        c0 = _cpu()
        res = write_video(record, path, cameras=(camera,), width=width, height=height, fps=fps,
                          jobs=jobs)
        cpu = _cpu() - c0
    finally:
        if before is None:
            os.environ.pop("LP_NUM_THREADS", None)
        else:
            os.environ["LP_NUM_THREADS"] = before
    assert res.jobs == jobs, (res.jobs, jobs)
    return {"fps": res.frames_per_second, "loop_fps": res.loop_frames_per_second,
            "cpu_ms": 1000 * cpu / res.frames}


def main(argv: list[str] | None = None) -> int:
    from sim.render.workers import usable_cores

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--run", type=Path, default=None, help="run folder (default: synthetic)")
    parser.add_argument("--camera", default="overview")
    parser.add_argument("--frames", type=int, default=120, help="frames per measurement")
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument("--sizes", type=_sizes, default=_sizes("480x360"))
    parser.add_argument("--jobs", type=int, default=usable_cores(),
                        help="processes of the parallel pipeline (default: usable cores)")
    parser.add_argument("--lp-threads", default=None,
                        help="LP_NUM_THREADS of the parallel pipeline's workers (default: 1)")
    parser.add_argument("--gl", choices=("egl", "osmesa"), default=None)
    parser.add_argument("--repeat", type=int, default=1,
                        help="measure each variant N times, interleaved, keep the best "
                             "(noisy hosts)")
    parser.add_argument("--json", type=Path, default=None, help="also write the results here")
    args = parser.parse_args(argv)

    backend = configure_gl(args.gl)
    import mujoco

    from sim.render.synthetic import write_synthetic_run
    from sim.simulation.runfolder import load_run

    n = args.jobs
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="bench_video_") as tmp_name:
        tmp = Path(tmp_name)
        if args.run is None:
            duration = (args.frames - 1) / args.fps + 0.01  # samples end at a multiple of 10 ms
            run_dir = write_synthetic_run(tmp / "run", duration=duration)
            fps = args.fps
        else:
            run_dir = args.run
            fps = args.frames / load_run(run_dir).duration  # the run's whole length
        record = load_run(run_dir)
        frames = int(np.floor(record.duration * fps + 1e-9)) + 1
        print(f"# backend={backend} mujoco={mujoco.__version__} python={platform.python_version()} "
              f"machine={platform.machine()} cores={usable_cores()} frames={frames} "
              f"camera={args.camera} LP_NUM_THREADS={os.environ.get('LP_NUM_THREADS', 'unset')}")
        print(f"# load average before: {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}")
        header = (f"{'size':>10} {'raw':>6} {'raw1':>6} {'pipe 1':>7} {f'pipe {n}':>7} "
                  f"{f'loop {n}':>7} {f'{n}/raw':>6} {f'{n}/raw1':>7}   CPU ms/frame: "
                  f"raw raw1 pipe1 pipe{n}")
        results = []
        for width, height in args.sizes:
            best: dict[str, float] = {}
            cpu: dict[str, float] = {}

            def keep(key: str, value: dict, best: dict = best, cpu: dict = cpu) -> None:
                if value["fps"] > best.get(key, 0.0):
                    best[key] = value["fps"]
                    cpu[key] = value["cpu_ms"]
                    if "loop_fps" in value:
                        best[key + "_loop"] = value["loop_fps"]

            gl_name, settings = "?", {}
            for _ in range(max(1, args.repeat)):
                raw = bench_raw(run_dir, backend, args.camera, width, height, fps, frames, None)
                gl_name, settings = raw["gl"], raw.get("settings", {})
                keep("raw", raw)
                keep("raw1", bench_raw(run_dir, backend, args.camera, width, height, fps,
                                       frames, "1"))
                keep("pipe1", bench_pipeline(record, tmp / "p1.mp4", args.camera, width, height,
                                             fps, 1, None))
                keep("pipeN", bench_pipeline(record, tmp / "pn.mp4", args.camera, width, height,
                                             fps, n, args.lp_threads))
            if not results:
                print(f"# OpenGL renderer: {gl_name}")
                print(f"# raw: one process, the pipeline's scene without overlay/caption/encoding "
                      f"({', '.join(f'{k}={v}' for k, v in settings.items())}), llvmpipe threads "
                      f"as the environment has them; raw1: the same with LP_NUM_THREADS=1 "
                      f"(one process on one core)")
                print(f"# pipe {n}: write_video with {n} processes, whole call (start-up "
                      f"included); {n}/raw and {n}/raw1: its frames/s over each baseline's")
                print(header)
            row = {
                "width": width, "height": height, "frames": frames, "jobs": n,
                "gl_renderer": gl_name, "raw_fps": best["raw"], "raw1_fps": best["raw1"],
                "pipeline1_fps": best["pipe1"], "pipelineN_fps": best["pipeN"],
                "pipelineN_loop_fps": best["pipeN_loop"],
                "ratio_to_raw": best["pipeN"] / best["raw"],
                "ratio_to_raw1": best["pipeN"] / best["raw1"],
                "cpu_ms_per_frame": cpu,
            }
            results.append(row)
            print(f"{width:>5}x{height:<4} {best['raw']:6.2f} {best['raw1']:6.2f} "
                  f"{best['pipe1']:7.2f} {best['pipeN']:7.2f} {best['pipeN_loop']:7.2f} "
                  f"{row['ratio_to_raw']:6.2f} {row['ratio_to_raw1']:7.2f}   "
                  f"{cpu['raw']:.0f} {cpu['raw1']:.0f} {cpu['pipe1']:.0f} {cpu['pipeN']:.0f}",
                  flush=True)
            # a loaded machine slows the wall clock far more than the CPU time per frame
            ceiling = min(n, usable_cores()) * 1000.0 / cpu["pipeN"]
            row["cpu_bound_pipelineN_fps"] = ceiling
            row["cpu_bound_ratio_to_raw1"] = ceiling * cpu["raw1"] / 1000.0
            print(f"# by CPU time: pipe {n} on {min(n, usable_cores())} idle cores at most "
                  f"{ceiling:.2f} frames/s = {row['cpu_bound_ratio_to_raw1']:.2f}x raw1 "
                  f"(1000 / {cpu['raw1']:.0f} ms = {1000.0 / cpu['raw1']:.2f} frames/s)",
                  flush=True)
    load1 = os.getloadavg()
    print(f"# load average after: {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")
    if args.json:
        args.json.write_text(json.dumps({"backend": backend, "results": results}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
