"""Shared pytest configuration for cellsim."""

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
