"""The shipped cells as files reproduce the Python-built cells' runs (issue 12): each shipped
scenario evaluated in memory with its cell built from models/cells/*.toml and from its Python
derivation (sim.cells.DERIVED), and the largest differences of the recorded arrays printed.

Run: ``.venv/bin/python benchmarks/shipped_cells_as_files.py`` (about a minute)
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sim.cells import DERIVED  # noqa: E402
from sim.core.resources import shipped_scenarios  # noqa: E402
from sim.pipeline.run import evaluate_scenario  # noqa: E402
from sim.scenario import load_scenario  # noqa: E402

for name, path in shipped_scenarios().items():
    sc = load_scenario(path)
    if sc.cell is None:
        print(f"{name}: bare scene (no cell)")
        continue
    t0 = time.time()
    a = evaluate_scenario(dataclasses.replace(sc, cell=DERIVED[sc.cell.name]))
    b = evaluate_scenario(sc)
    ra, rb = a.record.arrays, b.record.arrays
    out = {k: float(np.abs(ra[k] - rb[k]).max()) for k in ("q", "tau", "tcp_pos", "qpos") if k in ra}
    peak = float(np.abs(ra["tau"]).max())
    print(f"{name}: max |diff| q {out['q']:.2e} rad, tau {out['tau']:.2e} N m (peak {peak:.1f}), "
          f"tcp {out['tcp_pos']:.2e} m, qpos {out['qpos']:.2e}; verdict {a.summary['verdict']}/{b.summary['verdict']}; "
          f"collisions {len(a.summary['collisions'])}/{len(b.summary['collisions'])} ({time.time()-t0:.0f} s)", flush=True)
