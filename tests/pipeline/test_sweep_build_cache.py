"""A sweep's variants of one plan reuse their composed cell (issue 29:
:mod:`sim.simulation.build_cache`) and their reference's singularity measures
(:mod:`sim.simulation.singularity_cache`). Specification: the sweep's rows are those of each
variant evaluated alone, with nothing kept (no plan, scan, cell, measures or seam answers) and
its cell built in full, bit for bit. A planted cell cache that forgets the payload's inertia is
caught by the same comparison.

The scenario: the LR Mate 200iC/5L on the weld table with its torch, a joint move of 1.2 s;
payloads 1, 3 and 12 kg at speed scales 1 and 1.7 (two plans, one composed cell).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from support.scenarios import joint_phase, write_scenario

from sim.pipeline import run as run_module
from sim.pipeline.sweep import Variant, reuse, run_sweep
from sim.pipeline.sweep.evaluation import evaluate_variant
from sim.simulation import build_cache, collision_reuse, seam_measure, singularity_cache
from sim.simulation.compile import build

ROWS = [[0, 20, -60, 0, -30, 0], [0, 8, -60, 0, -30, 0], [0, 20, -60, 0, -30, 0]]
PAYLOADS = [1.0, 3.0, 12.0]
SPEEDS = [1.0, 1.7]


def _forget_everything() -> None:
    run_module._PLANS.clear()
    collision_reuse.clear_cache()
    build_cache.clear()
    singularity_cache.clear()
    seam_measure.clear_caches()


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    return write_scenario(tmp_path, "lrmate200ic5l",
                          [joint_phase(ROWS, time_s=[0.0, 0.6, 1.2], planner="546")],
                          cell="weld_table", tool="mig_torch", payload_kg=1.0)


@pytest.fixture(autouse=True)
def fresh(monkeypatch: pytest.MonkeyPatch) -> Any:
    _forget_everything()
    monkeypatch.setattr(reuse, "ENABLED", True)
    yield
    _forget_everything()


def _text(rows: list[dict]) -> list[str]:
    """Rows as exact text (repr of a float round-trips its bits; NaN equals NaN)."""
    return [json.dumps({k: repr(v) for k, v in r.items()}, sort_keys=True) for r in rows]


def _swept(scenario: Path, tmp_path: Path) -> dict[tuple[float, float], list[str]]:
    res = run_sweep(scenario, PAYLOADS, SPEEDS, evaluate_variant, workers=1,
                    out_dir=tmp_path / "sweep", progress=False, write=False,
                    raise_on_failure=False)
    assert not res.failures, [o.error for o in res.failures]
    return {(o.variant.payload_kg, o.variant.speed_scale): _text(list(o.rows))
            for o in res.outcomes}


def test_a_sweep_reusing_its_cell_gives_each_variant_s_rows_alone(
        scenario: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = {}
    with monkeypatch.context() as m:
        m.setattr(run_module, "build_reusing", build)  # each cell built in full
        for p in PAYLOADS:
            for v in SPEEDS:
                _forget_everything()
                alone[(p, v)] = _text(list(evaluate_variant(Variant(p, v, scenario)).rows))
    _forget_everything()
    composed = [0]
    real = build_cache.compose

    def counting(sc: Any) -> Any:
        composed[0] += 1
        return real(sc)

    monkeypatch.setattr(build_cache, "compose", counting)
    assert _swept(scenario, tmp_path) == alone
    assert composed[0] == 1  # one composed cell for the three payloads and two speeds

    # planted fault: a kept cell whose payload keeps the first variant's inertia
    _forget_everything()
    def forgets_inertia(kept: Any, mass: float, inertia: float, radius: float) -> None:
        kept.spec.body(build_cache.PAYLOAD).mass = mass
        kept.spec.geom(build_cache.PAYLOAD).size = [radius, 0.0, 0.0]

    monkeypatch.setattr(build_cache, "_set_payload", forgets_inertia)
    swept = _swept(scenario, tmp_path)
    first = (PAYLOADS[0], SPEEDS[0])
    assert swept[first] == alone[first]
    assert swept != alone, "the comparison missed a kept cell without its payload's inertia"
