"""Figures of the weld programs (issue 14), measured on the simulated tool point against
geometry written here (not the run's own summary):

* two lines at 90 deg with blend_mm = 5: speed through the corner, distance from the corner's
  polyline, closest approach to the corner; the same without blend (the stop);
* each weave pattern on a line (3 mm, 2 Hz, 8 mm/s): amplitude, FFT frequency, centre line,
  travel speed;
* tests/data/weld1.ls run as a TP program: FINE points, L/C speeds, J at 50 %;
* export of lrmate200ic_weld_plate then import: the programmed points on both tool paths;
* planning time of a woven phase against a plain one (IK samples and the joint polynomial).

Run: ``.venv/bin/python benchmarks/weld_programs_figures.py``
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "scenario"))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

from support import DATA  # noqa: E402
from support.scenarios import TP_SCENARIO  # noqa: E402
from test_weld_programs import (  # noqa: E402
    F0,
    A,
    B,
    C,
    corner,
    fft_frequency,
    to_polyline,
    weave_scenario,
    window,
)

from sim.pipeline.run import evaluate_scenario  # noqa: E402
from sim.scenario import load_scenario  # noqa: E402


def run(root: Path, text: str, name: str):
    (root / name).write_text(text)
    ev = evaluate_scenario(load_scenario(root / name))
    return ev, ev.record.arrays


with tempfile.TemporaryDirectory() as tmp:
    root = Path(tmp)
    for label, blend in (("blend_mm = 5", "blend_mm = 5.0"), ("no blend", "")):
        ev, a = run(root, corner(blend), f"c{len(blend)}.toml")
        t, p = window(a, ev, "leg1", "leg2")
        v = np.linalg.norm(np.gradient(p, t, axis=0), axis=1)
        d = np.linalg.norm(p - (C + F0), axis=1)
        near = d < 0.015
        print(f"corner, {label}: speed within 15 mm of the corner {1e3 * v[near].min():.3f}.."
              f"{1e3 * v[near].max():.3f} mm/s (set 20), max distance from the polyline "
              f"{1e3 * to_polyline(p, A + F0, C + F0, B + F0).max():.3f} mm, closest to the "
              f"corner {1e3 * d.min():.3f} mm")
    for pattern in ("sine", "zigzag", "triangle", "circle"):
        ev, a = run(root, weave_scenario(pattern), f"w_{pattern}.toml")
        t, p = window(a, ev, "weld")
        u = (C - A) / np.linalg.norm(C - A)
        lat_dir = np.cross(u, [0.0, 0.0, -1.0])
        full = (t > t[0] + 1.0) & (t < t[-1] - 1.0)
        tt, pp = t[full], p[full]
        whole = tt <= tt[0] + int((tt[-1] - tt[0]) * 2.0) / 2.0
        tt, pp = tt[whole], pp[whole]
        lat = (pp - (A + F0)) @ lat_dir
        print(f"weave {pattern:8s}: amplitude {1e3 * (lat.max() - lat.min()) / 2:.4f} mm (set 3), "
              f"frequency {fft_frequency(tt, lat):.5f} Hz (set 2), centre {1e3 * lat.mean():+.5f}"
              f" mm, travel {1e3 * np.polyfit(tt, (pp - (A + F0)) @ u, 1)[0]:.5f} mm/s (set 8)")
    (root / "weld1.ls").write_text((DATA / "weld1.ls").read_text())
    ev, a = run(root, TP_SCENARIO, "tp.toml")
    robot = load_scenario(root / "tp.toml").robot
    names = [x["name"] for x in ev.summary["phases"]]
    for name, P in (("line009_J", [450, -50, 50]), ("line010_L", [450, -50, 0]),
                    ("line013_C", [550, 50, 0])):
        j = int(np.argmin(np.abs(a["t"] - ev.summary["phases"][names.index(name)]["t1"])))
        err = np.linalg.norm(a["tcp_pos"][j] - (np.array(P) * 1e-3 + F0)) * 1e3
        print(f"TP weld1.ls: {name} FINE point reached within {err:.5f} mm (simulated tcp)")
    for c in ev.summary["cartesian_speed"]:
        print(f"TP weld1.ls: {c['phase']} cruise {c['cruise_mm_s']:.4f} mm/s (set {c['set_mm_s']:g})")
    sel = a["phase"] == 0
    ratio = np.abs(a["qd_ref"][sel]).max(axis=0) / np.asarray(robot.max_speed)
    print(f"TP weld1.ls: J P[1] 50%: largest peak joint speed {100 * ratio.max():.3f} % of its limit")

    subprocess.run([sys.executable, "-m", "sim", "export", "lrmate200ic_weld_plate", "--out",
                        str(root / "prog.ls")], capture_output=True, text=True)
    from sim.core.resources import shipped_scenarios
    from sim.scenario.fanuc_ls import read_ls

    prog = read_ls(root / "prog.ls")
    (root / "back.toml").write_text('name = "back"\ndescription = "x"\nrobot = "lrmate200ic5l"\n'
                                    'cell = "weld_table"\ntool = "mig_torch"\nprogram = "prog.ls"\n')
    orig = evaluate_scenario(load_scenario(shipped_scenarios()["lrmate200ic_weld_plate"]))
    back = evaluate_scenario(load_scenario(root / "back.toml"))
    T = orig.built.context.world_from_frame0
    po, pb = orig.record.arrays["tcp_pos_ref"], back.record.arrays["tcp_pos_ref"]
    worst = 0.0
    n = 0
    for k, pos in prog.positions.items():
        if pos.xyzwpr is None:
            continue
        p = T[:3, :3] @ (np.array(pos.xyzwpr[:3]) * 1e-3) + T[:3, 3]
        worst = max(worst, abs(np.linalg.norm(po - p, axis=1).min()
                               - np.linalg.norm(pb - p, axis=1).min()))
        n += 1
    print(f"export/import of lrmate200ic_weld_plate: {n} Cartesian points, largest difference "
          f"of the two tool paths' distances to them {1e3 * worst:.5f} mm; verdict "
          f"{back.summary['verdict']}")

    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    for pattern in (None, "sine", "zigzag"):
        text = weave_scenario(pattern or "sine")
        if pattern is None:
            text = text.split("[phases.weave]")[0]
        (root / "p.toml").write_text(text)
        s = load_scenario(root / "p.toml")
        built = build(s)
        t0 = time.perf_counter()
        m = build_motion(s, built.context)
        dt = time.perf_counter() - t0
        print(f"planning a 12.5 s line, weave {pattern}: {dt:.3f} s, "
              f"{len(m.phases[1].knot_times)} IK samples")
