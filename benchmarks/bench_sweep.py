"""Benchmark of parallel sweeps: serial vs process-pool wall time of ``sim.pipeline.sweep.run_sweep``.

By default every variant runs a stand-in workload that is shaped like ``cellsim run``: a
two-link MuJoCo arm with the payload on its tip, PD-tracking a sine reference whose period is
divided by the speed scale, for ``--sim-time`` seconds at 1 kHz, plus the inverse dynamics of
the reference, written to ``trajectory.npz``. Pass ``--runner module:function`` (and
``--scenario``) to time the real runner instead; it must accept a :class:`sim.pipeline.sweep.Variant`
and return its run folder.

Usage::

    .venv/bin/python benchmarks/bench_sweep.py                       # stand-in runner
    .venv/bin/python benchmarks/bench_sweep.py --payloads 0,2.5,5 --speeds 0.5,1,1.5 \\
        --workers 2 --json bench_sweep.json
    .venv/bin/python benchmarks/bench_sweep.py --runner sim.cli.size:run_variant --scenario bugnar_5r_weld_cycle
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sim.pipeline.sweep import Variant, parse_float_list, run_sweep  # noqa: E402

_ARM = """
<mujoco model="two_link">
  <option timestep="0.001" integrator="implicitfast"/>
  <worldbody>
    <body name="upper">
      <joint name="j1" type="hinge" axis="0 1 0" armature="0.1" damping="0.5"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04" mass="4"/>
      <body name="fore" pos="0.4 0 0">
        <joint name="j2" type="hinge" axis="0 1 0" armature="0.05" damping="0.3"/>
        <geom type="capsule" fromto="0 0 0 0.35 0 0" size="0.03" mass="2"/>
        <body name="tip" pos="0.35 0 0"><geom type="sphere" size="0.03" mass="0.01"/></body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="j1" forcerange="-200 200" forcelimited="true"/>
    <motor joint="j2" forcerange="-100 100" forcelimited="true"/>
  </actuator>
</mujoco>
"""

SIM_TIME = 4.0  # s of simulated time per variant (overridden by --sim-time through the env)


def standin_runner(variant: Variant) -> Path:
    """Simulate the two-link arm for one variant and write its run folder."""
    import mujoco

    sim_time = float(os.environ.get("BENCH_SWEEP_SIM_TIME", SIM_TIME))
    model = mujoco.MjModel.from_xml_string(_ARM)
    model.body_mass[model.body("tip").id] += variant.payload_kg
    data = mujoco.MjData(model)
    T = 2.0 / variant.speed_scale  # base period 2 s, knot times divided by the scale
    w = 2 * np.pi / T
    amp = np.array([0.8, 1.2])
    n = int(round(sim_time / model.opt.timestep)) + 1
    t = np.arange(n) * model.opt.timestep
    q_ref = amp * np.sin(w * t)[:, None]
    qd_ref = amp * w * np.cos(w * t)[:, None]
    qdd_ref = -amp * w * w * np.sin(w * t)[:, None]
    kp, kv = np.array([3000.0, 1500.0]), np.array([300.0, 150.0])
    q = np.empty((n, 2))
    qd = np.empty((n, 2))
    tau = np.empty((n, 2))
    tau_id = np.empty((n, 2))
    inv = mujoco.MjData(model)
    for i in range(n):
        # inverse dynamics of the reference (feed-forward and tau_id)
        inv.qpos[:], inv.qvel[:], inv.qacc[:] = q_ref[i], qd_ref[i], qdd_ref[i]
        mujoco.mj_inverse(model, inv)
        tau_id[i] = inv.qfrc_inverse
        data.ctrl[:] = tau_id[i] + kp * (q_ref[i] - data.qpos) + kv * (qd_ref[i] - data.qvel)
        q[i], qd[i] = data.qpos, data.qvel
        mujoco.mj_step(model, data)
        tau[i] = data.actuator_force
    run_dir = Path(variant.run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    np.savez(run_dir / "trajectory.npz", t=t, phase=np.zeros(n, dtype=int), q_ref=q_ref,
             qd_ref=qd_ref, qdd_ref=qdd_ref, q=q, qd=qd, tau=tau, tau_id=tau_id)
    (run_dir / "summary.json").write_text(json.dumps(
        {"scenario": str(variant.scenario), "robot": "two_link", "joints": ["j1", "j2"],
         "duration_s": sim_time}))
    return run_dir


def _load_runner(spec: str):
    module, _, name = spec.partition(":")
    if not name:
        raise SystemExit(f"--runner: expected module:function, got {spec!r}")
    return getattr(importlib.import_module(module), name)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--payloads", default="0,2.5,5", help="kg, e.g. 0,2.5,5 or 0:5:2.5")
    ap.add_argument("--speeds", default="0.5,1,1.5", help="speed scales, e.g. 0.5,1,1.5")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="parallel workers (default: all cores)")
    ap.add_argument("--runner", default=None, help="module:function (default: stand-in arm)")
    ap.add_argument("--scenario", default="standin", help="base scenario given to the runner")
    ap.add_argument("--sim-time", type=float, default=SIM_TIME,
                    help="simulated seconds per variant for the stand-in runner")
    ap.add_argument("--repeat", type=int, default=1, help="repeat each timing, keep the best")
    ap.add_argument("--json", type=Path, default=None, help="write the numbers here")
    args = ap.parse_args(argv)

    payloads = parse_float_list(args.payloads, "--payloads")
    speeds = parse_float_list(args.speeds, "--speeds")
    runner = _load_runner(args.runner) if args.runner else standin_runner
    os.environ["BENCH_SWEEP_SIM_TIME"] = str(args.sim_time)  # inherited by spawned workers
    n_var = len(payloads) * len(speeds)

    def cpu_s() -> float:
        own = resource.getrusage(resource.RUSAGE_SELF)
        kids = resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

    def timed(workers: int) -> tuple[float, float, list]:
        best, cpu, rows = float("inf"), 0.0, []
        for _ in range(max(args.repeat, 1)):
            with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
                c0, t0 = cpu_s(), time.perf_counter()
                res = run_sweep(args.scenario, payloads, speeds, runner, workers=workers,
                                out_dir=tmp, progress=False)
                wall = time.perf_counter() - t0
                if wall < best:
                    best, cpu = wall, cpu_s() - c0
                rows = [{k: v for k, v in r.items() if k != "run_dir"} for r in res.rows]
        return best, cpu, rows

    load_before = os.getloadavg()[0]
    serial_s, serial_cpu, serial_rows = timed(1)
    parallel_s, parallel_cpu, parallel_rows = timed(args.workers)
    same = json.dumps(serial_rows, default=str) == json.dumps(parallel_rows, default=str)
    speedup = serial_s / parallel_s
    eff_workers = min(args.workers, n_var)
    out = {
        "variants": n_var, "workers": args.workers, "cpu_count": os.cpu_count(),
        "runner": args.runner or "standin_runner", "sim_time_s": args.sim_time,
        "serial_s": serial_s, "parallel_s": parallel_s, "speedup": speedup,
        "efficiency": speedup / eff_workers, "identical_tables": same,
        "serial_cpu_s": serial_cpu, "parallel_cpu_s": parallel_cpu,
        "parallel_cores_busy": parallel_cpu / parallel_s, "load_avg_1min_before": load_before,
        "python": platform.python_version(), "machine": platform.machine(),
    }
    print(f"{n_var} variants, {args.workers} workers on {os.cpu_count()} cores: serial "
          f"{serial_s:.2f} s, parallel {parallel_s:.2f} s, speed-up {speedup:.2f}x "
          f"(efficiency {out['efficiency']:.0%}); CPU {serial_cpu:.2f} s serial, "
          f"{parallel_cpu:.2f} s parallel ({out['parallel_cores_busy']:.2f} cores busy); "
          f"load before {load_before:.2f}; tables identical: {same}")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2) + "\n")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
