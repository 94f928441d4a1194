"""What the sweep-reuse tests share: a short weld-table scenario, rows as exact text, forgetting
everything a process keeps between variants, and counting the cells :mod:`build_cache`
composes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from sim.pipeline import run as run_module
from sim.simulation import build_cache, collision_reuse, seam_measure, singularity_cache
from support.scenarios import joint_phase, write_scenario

#: The LR Mate 200iC/5L's joint rows (deg) of the short move: its torch passes 57 mm above
#: the weld table's base plate (a clearance, no collision).
ROWS = [[0, 20, -60, 0, -30, 0], [0, 8, -60, 0, -30, 0], [0, 20, -60, 0, -30, 0]]


def short_weld_scenario(folder: Path) -> Path:
    """The LR Mate 200iC/5L on the weld table with its torch, :data:`ROWS` in 1.2 s (5-4-6),
    1 kg of payload."""
    return write_scenario(folder, "lrmate200ic5l",
                          [joint_phase(ROWS, time_s=[0.0, 0.6, 1.2], planner="546")],
                          cell="weld_table", tool="mig_torch", payload_kg=1.0)


def rows_text(rows: list[dict[str, Any]]) -> list[str]:
    """Rows as exact text (repr of a float round-trips its bits; NaN equals NaN)."""
    return [json.dumps({k: repr(v) for k, v in r.items()}, sort_keys=True) for r in rows]


def forget_everything() -> None:
    """Nothing kept from an earlier variant: plans, reference scans, cells, singularity
    measures, seam paths and answers."""
    run_module._PLANS.clear()
    collision_reuse.clear_cache()
    build_cache.clear()
    singularity_cache.clear()
    seam_measure.clear_caches()


def count_composes(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """A counter (one item) of the cells :mod:`build_cache` composes from now on (a reused
    cell composes none); what it kept before is forgotten."""
    calls = [0]
    real = build_cache.compose

    def counting(scenario: Any) -> Any:
        calls[0] += 1
        return real(scenario)

    monkeypatch.setattr(build_cache, "compose", counting)
    build_cache.clear()
    return calls
