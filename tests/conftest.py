"""Shared pytest configuration for cellsim: its fixtures apply to every test folder.

The tests mirror the packages they specify (``tests/planners/``, ``tests/robots/``,
``tests/cells/``, ``tests/scenario/``, ``tests/simulation/``, ``tests/pipeline/``,
``tests/analysis/``, ``tests/render/``, ``tests/cli/``, ``tests/api/``), with
``tests/campaigns/`` for the campaigns across packages and ``tests/house/`` for the house rules
(layers, packaging). Test files have unique names (pytest's default import mode). This folder is
on ``sys.path`` (it holds this conftest.py), so every test imports the oracles and factories of
``tests/support/`` as ``support``; ``tests/data/`` holds the data files (``support.DATA``).
"""

from __future__ import annotations

import os

# Headless rendering: choose EGL by default before anything imports mujoco; sim.render.gl may
# override this with a working backend.
os.environ.setdefault("MUJOCO_GL", "egl")


import pytest  # noqa: E402


@pytest.fixture(scope="session")
def scenario_run(tmp_path_factory, worker_id):
    """``scenario_run(name) -> (run_dir, summary)``: each shipped scenario simulated once per
    test session (no video, no plots), shared by every test that checks its results.

    Under pytest-xdist the workers share one folder of runs (this session's base temporary
    folder): the first worker that needs a scenario runs it while holding a lock on its folder,
    the others wait for the lock and read the finished run. ``summary`` is always the written
    ``summary.json`` read back, whichever worker ran it.
    """
    import fcntl
    import json

    from sim.pipeline.run import RunOptions, run_scenario
    from sim.scenario import load_scenario
    from sim.simulation.runfolder import is_run_folder, marker_state

    base = tmp_path_factory.getbasetemp()
    root = (base if worker_id == "master" else base.parent) / "scenario_runs"
    root.mkdir(parents=True, exist_ok=True)
    cache: dict = {}

    def get(name: str):
        if name not in cache:
            out = root / name
            with open(root / f"{name}.lock", "w") as lock:
                fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
                if not (is_run_folder(out) and marker_state(out) == "complete"):
                    run_scenario(load_scenario(name), RunOptions(
                        out_dir=out, video=False, plots=False, progress=False))
            cache[name] = (out, json.loads((out / "summary.json").read_text()))
        return cache[name]

    return get
