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
def scenario_run(tmp_path_factory):
    """``scenario_run(name) -> (run_dir, summary)``: each shipped scenario simulated once per
    test session (no video, no plots), shared by every test that checks its results."""
    from sim.pipeline.run import RunOptions, run_scenario
    from sim.scenario import load_scenario

    root = tmp_path_factory.mktemp("scenario_runs")
    cache: dict = {}

    def get(name: str):
        if name not in cache:
            out = root / name
            summary = run_scenario(load_scenario(name), RunOptions(
                out_dir=out, video=False, plots=False, progress=False))
            cache[name] = (out, summary)
        return cache[name]

    return get
