"""Torque figures of the shipped scenarios, each against an independent computation.

Prints, for every shipped scenario (or those named):

* timestep convergence: the worst relative difference, over the joints whose peak is over 2 %
  of the largest, of the peak and RMS of ``tau_id`` and ``tau`` between 1 ms and 0.25 ms steps;
* the worst |pinocchio RNEA + damping + Coulomb - tau_id| / joint peak where |qd| > 1e-2 rad/s,
  on the run's own ``model.xml`` (pinocchio: the ``pin`` test dependency);

and the energy balance of a closed frictionless cycle: the largest |work of tau_id - change of
kinetic + potential energy| over the cycle / its gross energy. These are the quantities
``tests/simulation/test_torques.py`` bounds (1 %, 1e-6, 1e-4).

Usage: python benchmarks/torque_figures.py [SCENARIO ...]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import mujoco
import numpy as np

TESTS = Path(__file__).resolve().parents[1] / "tests"
sys.path[:0] = [str(TESTS / "simulation"), str(TESTS)]
import test_torques as T  # noqa: E402  (the tests' own helpers, so the figures are theirs)

from sim.analysis.sizing import peak_abs, rms  # noqa: E402
from sim.core.resources import shipped_scenarios  # noqa: E402
from sim.pipeline.run import RunOptions, run_scenario  # noqa: E402
from sim.robots.registry import coulomb  # noqa: E402
from sim.scenario import load_scenario, parse_scenario  # noqa: E402
from sim.simulation.compile import build  # noqa: E402
from sim.simulation.motion import build_motion  # noqa: E402
from sim.simulation.simulate import inverse_dynamics  # noqa: E402


def convergence(name: str) -> float:
    stats = {}
    for h in (0.001, 0.00025):
        a = T._simulate(load_scenario(name), h)
        stats[h] = np.array([[[peak_abs(a["t"], a[k][:, j])[0], rms(a["t"], a[k][:, j])]
                              for j in range(a[k].shape[1])] for k in ("tau_id", "tau")])
    coarse, fine = stats[0.001], stats[0.00025]
    worst = 0.0
    for c, f in zip(coarse, fine):
        loaded = f[:, 0] > 0.02 * f[:, 0].max()
        worst = max(worst, float(np.max(np.abs(c[loaded] - f[loaded]) / f[loaded])))
    return 100.0 * worst


def rnea_error(name: str, tmp: Path) -> float:
    out = tmp / name
    summary = run_scenario(load_scenario(name), RunOptions(out_dir=out, video=False, plots=False,
                                                            progress=False))
    pin, model = T._pinocchio_model(out / "model.xml", tmp)
    mj = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    dof = np.array([mj.jnt_dofadr[mj.joint(f"robot/{j}").id] for j in summary["joints"]])
    friction = np.array([mj.actuator_forcerange[mj.actuator(f"robot/friction_{j}").id, 1]
                         for j in summary["joints"]])
    with np.load(out / "trajectory.npz") as z:
        a = {k: z[k] for k in ("q_ref", "qd_ref", "qdd_ref", "tau_id")}
    peak = np.abs(a["tau_id"]).max(axis=0)
    data, worst = model.createData(), 0.0
    for k in range(0, a["q_ref"].shape[0], max(1, a["q_ref"].shape[0] // 3000)):
        q, qd, qdd = a["q_ref"][k], a["qd_ref"][k], a["qdd_ref"][k]
        tau = np.array(pin.rnea(model, data, q, qd, qdd)) + mj.dof_damping[dof] * qd \
            + coulomb(friction, qd)
        moving = np.abs(qd) > 1e-2
        if moving.any():
            worst = max(worst, float(np.max(np.abs(tau - a["tau_id"][k])[moving] / peak[moving])))
    return worst


def energy_error() -> float:
    scenario = parse_scenario(T.CLOSED_CYCLE, source="closed_cycle.toml")
    built = build(scenario)
    model = built.model
    model.dof_damping[:] = 0.0
    built.cell.frictionloss[:] = 0.0
    motion = build_motion(scenario, built.context)
    t = np.linspace(motion.t0, motion.t1, 24001)
    ref = motion.at(t)
    power = np.einsum("ij,ij->i", inverse_dynamics(model, built, ref.q, ref.qd, ref.qdd), ref.qd)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    model.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)
    data, energy = mujoco.MjData(model), np.empty(t.size)
    for k in range(t.size):
        data.qpos[built.robot_qpos] = ref.q[k]
        data.qvel[:] = 0.0
        data.qvel[built.robot_dof] = ref.qd[k]
        mujoco.mj_forward(model, data)
        energy[k] = data.energy.sum()
    return float(np.abs(work - (energy - energy[0])).max() / np.trapezoid(np.abs(power), t))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*")
    names = ap.parse_args().scenarios or list(shipped_scenarios())
    print(f"{'scenario':32s} {'1 ms vs 0.25 ms, worst %':>25s} {'|RNEA - tau_id| / peak':>23s}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            print(f"{name:32s} {convergence(name):25.3f} {rnea_error(name, Path(tmp)):23.2e}")
    print(f"energy balance, closed frictionless cycle: max |W - dE| / gross = {energy_error():.2e}")


if __name__ == "__main__":
    main()
