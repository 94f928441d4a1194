"""Figures of the cell-file acceptance cell (issue 12) and of the OPW inverse kinematics
(issue 13), each recomputed independently of the code under test: the seam line, its end
points and the torch axis from the transforms written here, not from the loader; the OPW closed
form against the URDF joint product.

Run: ``.venv/bin/python benchmarks/cells_and_arms_figures.py``
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

from support.cell_files import (  # noqa: E402
    BRACKET_POS_MM,
    BRACKET_YAW_DEG,
    SEAM_MM,
    make_cell,
    rz,
)

from sim.pipeline.run import evaluate_scenario  # noqa: E402
from sim.robots.arm import load_arm  # noqa: E402
from sim.robots.kinematics import opw  # noqa: E402
from sim.robots.kinematics.numeric_ik import pose_error  # noqa: E402
from sim.scenario import load_scenario  # noqa: E402

with tempfile.TemporaryDirectory() as tmp:
    ev = evaluate_scenario(load_scenario(make_cell(Path(tmp))))
w = next(x for x in ev.summary["weld"] if x["phase"] == "weld")
print("summary weld:", {k: w[k] for k in ("max_path_deviation_mm", "travel_speed_mm_s", "travel_speed_cv", "torch_angle_error_deg")})
rec = ev.record.arrays
k = [p["name"] for p in ev.summary["phases"]].index("weld")
sel = (rec["phase"] == k) & rec["arc_on"].astype(bool)
R, t = rz(BRACKET_YAW_DEG), np.array(BRACKET_POS_MM) * 1e-3
a, b = (R @ (np.array(p) * 1e-3) + t for p in SEAM_MM)
u = (b - a) / np.linalg.norm(b - a)
p = rec["tcp_pos"][sel]
s = (p - a) @ u
print("independent: max off-line %.2e mm, start %.3e mm, end %.3e mm" % (
    np.linalg.norm((p - a) - np.outer(s, u), axis=1).max() * 1e3,
    np.linalg.norm(p[0] - a) * 1e3, np.linalg.norm(p[-1] - b) * 1e3))
ang = []
for q in rec["tcp_quat"][sel]:
    M = np.zeros(9); mujoco.mju_quat2Mat(M, q); ang.append(M.reshape(3, 3)[:, 2] @ -(R @ [0, 0, 1]))
print("independent: torch to -normal max %.2e deg" % np.degrees(np.arccos(np.clip(min(ang), -1, 1))))
print("collisions", ev.summary["collisions"], "verdict", ev.summary["verdict"])

for name in ("kuka_kr6r700sixx", "kuka_kr6r900_2"):
    arm = load_arm(ROOT / "tests" / "data" / f"{name}.urdf")
    Q = np.random.default_rng(3).uniform(arm.chain.lower, arm.chain.upper, size=(1000, 6))
    fk = max(np.abs(opw.forward(arm.opw, Q)[i] - arm.chain.fk(Q[i])).max() for i in range(1000))
    worst = max(np.linalg.norm(pose_error(arm.fk(s.q), arm.fk(q))) for q in Q for s in arm.ik(arm.fk(q)))
    print(f"{name}: OPW vs URDF chain FK max {fk:.1e}; worst IK pose error {worst:.1e} (1000 poses)")
