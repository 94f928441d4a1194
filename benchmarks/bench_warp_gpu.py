"""The MuJoCo Warp batch of 1024 weld-plate variants on a GPU (issue 29), against MuJoCo in C.

What it measures, stage by stage, each timed on its own:

1. **host preparation**: the variants (payloads x speed scales of
   ``lrmate200ic_weld_plate``) built and planned as ``cellsim size --backend warp`` builds and
   plans them (``sim.pipeline.run._prepare``, a plan reused by the payloads of one speed);
2. **Warp's kernels**: a first batch of two variants over 0.01 s compiles them (cached after);
3. **the batch**: every variant simulated as one batch by
   :func:`sim.simulation.warp_batch.simulate_batch` over the same window of the cycle (the
   drives' motor limit on, as the scenario sets it). Its stepping is timed inside the call
   (``SimulationRecord.wall_s`` times the worlds); the call's wall adds the host's references
   and inverse-dynamics feed-forward, and the arrays' assembly;
4. **MuJoCo in C** (:func:`sim.simulation.simulate.simulate`, one variant at a time, this
   machine's CPU) on a few of the same variants over the same window: its time per variant and
   the batch's agreement with it (joint paths in rad, actuator torques relative to the
   joint's peak), as ``tests/simulation/test_warp_backend.py`` bounds them.

It prints the ratios: the batch's simulated variant-seconds per wall second against one CPU
process's, and the batch's wall against the variants' CPU time shared by 2 and by all cores.
Each variant runs the first ``--window-s`` simulated seconds of its cycle (all of it with
``--window-s 0``): the host's references and feed-forward cost about 0.01 s per simulated
second per variant in one process, which for 1024 whole cycles (83 s each) would be about
15 minutes of host time, longer than a lent GPU is held.

    python benchmarks/bench_warp_gpu.py                       # 32 payloads x 32 speeds, 4 s
    python benchmarks/bench_warp_gpu.py --payloads 2 --speeds 2 --window-s 0.2 --device cpu

Without a GPU, Warp's CPU device runs 4 variants over 0.2 s (for the code path, not for
speed). ``CELLSIM_WARP_GRAPH=0`` (``--no-graph``) steps without CUDA graphs.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


class Window:
    """The first ``seconds`` of a motion (everything else as the motion says)."""

    def __init__(self, motion: Any, seconds: float) -> None:
        self._motion = motion
        self.duration = min(float(motion.duration), seconds) if seconds > 0 else motion.duration

    def __getattr__(self, name: str) -> Any:
        return getattr(self._motion, name)


def variants(scenario: str, payloads: int, speeds: int) -> list[tuple[float, float, Any]]:
    from sim.pipeline.sweep.evaluation import _variant_scenario
    from sim.pipeline.sweep.variants import Variant

    out = []
    for s in np.linspace(0.8, 1.2, speeds):
        for p in np.linspace(0.5, 3.0, payloads):
            v = Variant(index=len(out), scenario=scenario, payload_kg=round(float(p), 6),
                        speed_scale=round(float(s), 6))
            out.append((v.payload_kg, v.speed_scale, _variant_scenario(v)))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="lrmate200ic_weld_plate")
    ap.add_argument("--payloads", type=int, default=None,
                    help="payloads, 0.5-3 kg (default 32; 2 without a GPU)")
    ap.add_argument("--speeds", type=int, default=None,
                    help="speed scales, 0.8-1.2 (default 32; 2 without a GPU)")
    ap.add_argument("--window-s", type=float, default=None,
                    help="simulated seconds of each cycle (0: all of it; default 4, 0.2 "
                         "without a GPU)")
    ap.add_argument("--device", default=None, help="Warp device (default: cuda if found)")
    ap.add_argument("--parity", type=int, default=4,
                    help="variants also simulated by MuJoCo in C (default 4)")
    ap.add_argument("--no-graph", action="store_true",
                    help="step without CUDA graphs (each kernel launched from Python)")
    ap.add_argument("--compare-s", type=float, default=0.5,
                    help="also run the batch this many simulated seconds the other way "
                         "(with or without CUDA graphs) on a GPU; 0: not (default 0.5)")
    ap.add_argument("--json", type=Path, default=None, help="write the figures here too")
    args = ap.parse_args()

    from sim.pipeline.run import RunOptions, _drives, _feedforward, _prepare
    from sim.pipeline.stages import Stages
    from sim.simulation import warp_batch
    from sim.simulation.simulate import simulate

    if args.no_graph:
        os.environ["CELLSIM_WARP_GRAPH"] = "0"
    wp, _ = warp_batch._import_warp()
    device = args.device or warp_batch.default_device()
    dev = wp.get_device(device)
    out: dict[str, Any] = {"device": device, "device_name": dev.name,
                           "host": platform.processor() or platform.machine(),
                           "cpu_count": os.cpu_count(), "scenario": args.scenario}
    print(f"device {device}: {dev.name}; {os.cpu_count()} CPU cores", flush=True)
    small = not dev.is_cuda  # Warp's CPU device: the code path, not a speed figure
    args.payloads = args.payloads or (2 if small else 32)
    args.speeds = args.speeds or (2 if small else 32)
    if args.window_s is None:
        args.window_s = 0.2 if small else 4.0
    out["window_s"] = args.window_s
    if small:
        print("no GPU: Warp's CPU device runs a small batch (the code path, not a speed "
              "figure)", flush=True)

    def keep() -> None:  # the figures so far (a run stopped at a time limit keeps them)
        if args.json:
            args.json.write_text(json.dumps(out, indent=2) + "\n")

    # 1. host preparation
    t0 = time.perf_counter()
    vs = variants(args.scenario, args.payloads, args.speeds)
    opts = RunOptions(video=False, plots=False, progress=False, backend="warp")
    prepared = [_prepare(sc, opts, Stages(enabled=False), reuse_plan=True)[:2]
                for _, _, sc in vs]
    motions = [Window(m, args.window_s) for _, m in prepared]
    builts = [b for b, _ in prepared]
    out["prepare_s"] = time.perf_counter() - t0
    sc0 = vs[0][2]
    ff, settle = _feedforward(sc0, opts), float(sc0.simulation.settle_s) if args.window_s <= 0 \
        else 0.0
    drives = [_drives(sc) for _, _, sc in vs]
    labels = [f"{p:g} kg x{s:g}" for p, s, _ in vs]
    n = len(vs)
    dt = float(builts[0].model.opt.timestep)
    steps = [int(round((m.duration + settle) / dt)) for m in motions]
    out.update(variants=n, timestep_s=dt, steps_max=max(steps), steps_total=int(sum(steps)),
               drives=drives[0] is not None)
    print(f"{n} variants prepared in {out['prepare_s']:.1f} s; {max(steps)} steps each at "
          f"most ({dt * 1e3:g} ms), motor limit {'on' if drives[0] else 'off'}", flush=True)
    keep()

    # 2. the kernels
    t0 = time.perf_counter()
    warp_batch.simulate_batch(builts[:2], [Window(m, 0.01) for m in motions[:2]],
                              feedforward=ff, drives=drives[:2], device=device, labels=labels[:2])
    out["compile_s"] = time.perf_counter() - t0
    print(f"kernels compiled or loaded in {out['compile_s']:.1f} s", flush=True)
    keep()

    # 3. the batch
    t0 = time.perf_counter()
    recs = warp_batch.simulate_batch(builts, motions, feedforward=ff, settle_s=settle,
                                     drives=drives, device=device, labels=labels)
    out["batch_call_s"] = time.perf_counter() - t0
    out["batch_stepping_s"] = recs[0].wall_s * n
    sim_s = float(sum(s * dt for s in steps))
    out["variant_seconds_simulated"] = sim_s
    out["batch_sim_s_per_wall_s"] = sim_s / out["batch_stepping_s"]
    out["cuda_graph"] = bool(warp_batch.STEP_STATS["graph"])
    out["passes_per_step"] = warp_batch.STEP_STATS["steps"] / max(steps)
    out["ms_per_step"] = 1e3 * out["batch_stepping_s"] / max(steps)
    print(f"batch of {n}: stepping {out['batch_stepping_s']:.1f} s "
          f"({out['batch_sim_s_per_wall_s']:.0f} variant-seconds simulated per second), "
          f"whole call {out['batch_call_s']:.1f} s; "
          f"{out['ms_per_step']:.2f} ms per step of all {n} "
          f"({out['passes_per_step']:.2f} passes; CUDA graph {out['cuda_graph']})", flush=True)
    keep()
    if args.compare_s > 0 and dev.is_cuda:  # the same batch, a short window, the other way
        os.environ["CELLSIM_WARP_GRAPH"] = "1" if args.no_graph else "0"
        short = [Window(m, args.compare_s) for m in motions]
        k = int(round(min(m.duration for m in short) / dt))
        got = warp_batch.simulate_batch(builts, short, feedforward=ff, drives=drives,
                                        device=device, labels=labels)
        os.environ["CELLSIM_WARP_GRAPH"] = "0" if args.no_graph else "1"
        other = 1e3 * got[0].wall_s * n / k
        out["compare"] = {"window_s": args.compare_s, "cuda_graph": not out["cuda_graph"],
                          "ms_per_step": other,
                          "passes_per_step": warp_batch.STEP_STATS["steps"] / k}
        print(f"  the other way (CUDA graph {not out['cuda_graph']}), {args.compare_s:g} s: "
              f"{other:.2f} ms per step", flush=True)
        keep()

    # 4. MuJoCo in C on a few of the same variants
    pick = np.unique(np.linspace(0, n - 1, max(1, args.parity)).round().astype(int))
    cpu_s, call_s, dq, dtau, dpeak, drms = [], [], [], [], [], []
    for i in pick:
        t0 = time.perf_counter()
        rec = simulate(builts[i], motions[i], feedforward=ff, settle_s=settle, progress=False,
                       drives=drives[i])
        cpu_s.append(rec.wall_s)
        call_s.append(time.perf_counter() - t0)
        a, b = rec.arrays, recs[i].arrays
        dq.append(float(np.max(np.abs(a["q"] - b["q"]))))
        peak = np.maximum(np.max(np.abs(a["tau_actuator"]), axis=0), 1e-9)
        dtau.append(float(np.max(np.abs(a["tau_actuator"] - b["tau_actuator"]) / peak)))
        # each joint's peak and RMS torque, relative (joints carrying >= 2 % of the largest)
        big = peak >= 0.02 * peak.max()
        pb = np.max(np.abs(b["tau_actuator"]), axis=0)
        ra = np.sqrt(np.mean(a["tau_actuator"] ** 2, axis=0))
        rb = np.sqrt(np.mean(b["tau_actuator"] ** 2, axis=0))
        dpeak.append(float(np.max(np.abs(pb - peak)[big] / peak[big])))
        drms.append(float(np.max(np.abs(rb - ra)[big] / ra[big])))
        print(f"  {labels[i]}: MuJoCo {rec.wall_s:.2f} s ({time.perf_counter() - t0:.2f} s "
              f"with references); largest joint difference {dq[-1]:.2g} rad, torque "
              f"{100 * dtau[-1]:.2g} % of the joint's peak (peaks {100 * dpeak[-1]:.2g} %, "
              f"RMS {100 * drms[-1]:.2g} %)", flush=True)
    share = float(np.mean(steps)) / float(np.mean([steps[i] for i in pick]))
    per_variant_cpu = float(np.mean(cpu_s)) * share  # stepping
    per_call_cpu = float(np.mean(call_s)) * share  # with references, feed-forward, arrays
    out.update(parity_variants=[labels[i] for i in pick], cpu_simulate_s=cpu_s,
               cpu_call_s=call_s, cpu_s_per_variant=per_variant_cpu,
               cpu_call_s_per_variant=per_call_cpu, max_joint_diff_rad=max(dq),
               max_torque_diff_of_peak=max(dtau), max_peak_torque_rel_diff=max(dpeak),
               max_rms_torque_rel_diff=max(drms))
    cpu_sim_rate = sim_s / (per_variant_cpu * n)
    out["speedup_stepping_vs_one_cpu_process"] = out["batch_sim_s_per_wall_s"] / cpu_sim_rate
    # the whole call against the CPU path's whole simulate() (both compute the references,
    # the feed-forward and the arrays), shared by 2 and by every core
    out["speedup_call_vs_2_cpu_processes"] = per_call_cpu * n / 2 / out["batch_call_s"]
    out["speedup_call_vs_all_cpu_processes"] = \
        per_call_cpu * n / (os.cpu_count() or 1) / out["batch_call_s"]
    print(f"ratios: batch stepping {out['speedup_stepping_vs_one_cpu_process']:.1f}x one CPU "
          f"process ({cpu_sim_rate:.1f} variant-seconds per second); whole call "
          f"{out['speedup_call_vs_2_cpu_processes']:.2f}x 2 CPU processes, "
          f"{out['speedup_call_vs_all_cpu_processes']:.2f}x {os.cpu_count()} CPU processes",
          flush=True)
    keep()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
