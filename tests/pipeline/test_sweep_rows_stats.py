"""A metrics-only variant's rows take their peaks, RMS values, speeds and powers from the
sizing's statistics of the same arrays instead of computing them again (issue 29).
Specification: the rows are those computed from the arrays alone, bit for bit; statistics that
are not what the rows need (another window, a joint missing, float32 arrays) are not used; a
planted mix-up of the sizing's joints is caught by the comparison."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.analysis.sizing import size_trajectory
from sim.pipeline.sweep.variants import Variant, rows_from

JOINTS = ("j1", "j2", "j3")


def _arrays(seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    n = 300
    t = np.cumsum(rng.uniform(0.5e-3, 2e-3, n))
    out = {"t": t}
    for key in ("tau_id", "tau", "qd_ref", "qd", "qdd_ref"):
        out[key] = np.cumsum(rng.normal(size=(n, len(JOINTS))), axis=0) * 0.1
    return out


def _text(rows: list[dict]) -> list[str]:
    return [json.dumps({k: repr(v) for k, v in r.items()}, sort_keys=True) for r in rows]


def _rows(arrays: dict, stats: dict | None) -> list[str]:
    return _text(rows_from(Variant(1.0, 1.0, "x"), arrays, JOINTS, "pass", {}, "", stats=stats))


def _stats(arrays: dict) -> dict:
    return {j.joint: j.stats for j in size_trajectory(arrays, JOINTS).joints}


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**16))
def test_rows_from_the_sizing_are_the_computed_rows(seed: int) -> None:
    arrays = _arrays(seed)
    assert _rows(arrays, _stats(arrays)) == _rows(arrays, None)


def test_unfit_statistics_are_not_used() -> None:
    arrays, other = _arrays(1), _arrays(2)
    want = _rows(arrays, None)
    wrong = _stats(other)  # the statistics of other arrays: used, they would show
    assert _rows(arrays, wrong) != want
    missing = {k: v for k, v in wrong.items() if k != "j3"}
    assert _rows(arrays, missing) == want
    windowless = {k: {**v, "sim": v["id"]} for k, v in wrong.items()}
    assert _rows(arrays, windowless) == want
    f32 = {k: v.astype(np.float32) if k == "tau" else v for k, v in arrays.items()}
    assert _rows(f32, wrong) == _rows(f32, None)


def test_planted_joint_mix_up_is_caught() -> None:
    arrays = _arrays(3)
    stats = _stats(arrays)
    swapped = {"j1": stats["j2"], "j2": stats["j1"], "j3": stats["j3"]}
    assert _rows(arrays, swapped) != _rows(arrays, None)
