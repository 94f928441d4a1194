"""A sweep's variants of one plan reuse their composed cell (issue 29:
:mod:`sim.simulation.build_cache`) and their reference's singularity measures
(:mod:`sim.simulation.singularity_cache`). Specification: the sweep's rows are those of each
variant evaluated alone, with nothing kept (no plan, scan, cell, measures or seam answers) and
its cell built in full, bit for bit. A planted cell cache that forgets the payload's inertia is
caught by the same comparison.

The scenario: the LR Mate 200iC/5L on the weld table with its torch, a joint move of 1.2 s;
payloads 1, 0, 3 and 12 kg at speed scales 1 and 1.7 (two plans, one composed cell).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from support.sweeps import count_composes, forget_everything, rows_text, short_weld_scenario

from sim.pipeline import run as run_module
from sim.pipeline.sweep import Variant, reuse, run_sweep
from sim.pipeline.sweep.evaluation import evaluate_variant
from sim.simulation import build_cache
from sim.simulation.compile import build

PAYLOADS = [1.0, 0.0, 3.0, 12.0]  # 0 kg shares the cell too (a massless payload body)
SPEEDS = [1.0, 1.7]


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    return short_weld_scenario(tmp_path)


@pytest.fixture(autouse=True)
def fresh(monkeypatch: pytest.MonkeyPatch) -> Any:
    forget_everything()
    monkeypatch.setattr(reuse, "ENABLED", True)
    yield
    forget_everything()


def _swept(scenario: Path, tmp_path: Path) -> dict[tuple[float, float], list[str]]:
    res = run_sweep(scenario, PAYLOADS, SPEEDS, evaluate_variant, workers=1,
                    out_dir=tmp_path / "sweep", progress=False, write=False,
                    raise_on_failure=False)
    assert not res.failures, [o.error for o in res.failures]
    return {(o.variant.payload_kg, o.variant.speed_scale): rows_text(list(o.rows))
            for o in res.outcomes}


def test_a_sweep_reusing_its_cell_gives_each_variant_s_rows_alone(
        scenario: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    alone = {}
    with monkeypatch.context() as m:
        m.setattr(run_module, "build_reusing", build)  # each cell built in full
        for p in PAYLOADS:
            for v in SPEEDS:
                forget_everything()
                alone[(p, v)] = rows_text(list(evaluate_variant(Variant(p, v, scenario)).rows))
    forget_everything()
    composed = count_composes(monkeypatch)
    assert _swept(scenario, tmp_path) == alone
    assert composed[0] == 1  # one composed cell for the four payloads and two speeds

    # planted fault: a kept cell whose payload keeps the first variant's inertia
    forget_everything()
    def forgets_inertia(kept: Any, mass: float, inertia: float, radius: float,
                        rgba: tuple[float, ...]) -> None:
        kept.spec.body(build_cache.PAYLOAD).mass = mass
        kept.spec.geom(build_cache.PAYLOAD).size = [radius, 0.0, 0.0]
        kept.spec.geom(build_cache.PAYLOAD).rgba = list(rgba)

    monkeypatch.setattr(build_cache, "_set_payload", forgets_inertia)
    swept = _swept(scenario, tmp_path)
    first = (PAYLOADS[0], SPEEDS[0])
    assert swept[first] == alone[first]
    assert swept != alone, "the comparison missed a kept cell without its payload's inertia"
