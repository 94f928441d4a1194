"""Cost of collision checking: in a run, and in ``cellsim check``.

For each shipped scenario (or those named on the command line) this runs the scenario as
``cellsim run --no-video --no-plots`` does (simulation, summary, collisions and clearance,
sizing report) and prints:

* ``run_s``: the run's wall time;
* ``coll_s``: the collision and clearance check inside it (``summary["collision_check_s"]``);
* ``coll/rest``: the check's share over the rest of the run (goal: <= 0.30; with the video,
  which a default run also renders, the share is smaller still);
* ``check_s``: ``cellsim check SCENARIO`` as a fresh process (imports included; goal for the
  weld cycle: < 5 s).

Usage: python benchmarks/bench_collisions.py [SCENARIO ...]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from sim.core.resources import shipped_scenarios
from sim.pipeline.run import RunOptions, run_scenario
from sim.scenario import load_scenario


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenarios", nargs="*", help="scenario names (default: every shipped one)")
    args = ap.parse_args()
    names = args.scenarios or sorted(shipped_scenarios())
    print(f"{'scenario':34s} {'run_s':>7s} {'coll_s':>7s} {'coll/rest':>9s} {'check_s':>8s}")
    for name in names:
        with tempfile.TemporaryDirectory() as tmp:
            start = time.perf_counter()
            summary = run_scenario(load_scenario(name), RunOptions(
                out_dir=Path(tmp) / "run", video=False, plots=False, progress=False))
            run_s = time.perf_counter() - start
        coll = float(summary["collision_check_s"])
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "sim", "check", name], capture_output=True,
                       check=False)
        check_s = time.perf_counter() - start
        print(f"{name:34s} {run_s:7.2f} {coll:7.2f} {coll / (run_s - coll):9.3f} {check_s:8.2f}")


if __name__ == "__main__":
    main()
