""":func:`sim.analysis.statistics.sustained` keeps the window bounds of the latest times and
window (issue 29: a sizing takes every signal of a record over the same times). Specification:
whatever was asked before, the sustained signal is the one computed with nothing kept, bit for
bit, and it is the window mean of an independent oracle (:mod:`support.window_oracle`); times
that differ in one bit, or a different window, get their own bounds. A planted comparison of
the times that always matches is caught."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.window_oracle import window_mean

from sim.analysis import statistics
from sim.analysis.statistics import sustained


def _fresh(t: np.ndarray, x: np.ndarray, w: float) -> np.ndarray:
    statistics._WINDOWS.clear()
    return sustained(t, x, w)


def _record(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.5e-3, 2e-3, n))
    return t, rng.normal(size=(n, 2))


def _mismatches(cases: list[tuple[np.ndarray, np.ndarray, float]]) -> list[int]:
    """Each case asked in turn after the others (its bounds possibly kept), against the same
    case with nothing kept."""
    want = [_fresh(t, x, w) for t, x, w in cases]
    statistics._WINDOWS.clear()
    bad = []
    for _ in range(2):
        for k, (t, x, w) in enumerate(cases):
            if sustained(t, x, w).tobytes() != want[k].tobytes():
                bad.append(k)
    return bad


def _cases(seed: int) -> list[tuple[np.ndarray, np.ndarray, float]]:
    t, x = _record(seed, 400)
    t2 = t.copy()
    t2[200] = np.nextafter(t2[200], np.inf)  # one bit of one time
    t3 = t.copy()
    t3[200:] += 0.004  # a gap: the windows round it differ
    return [(t, x, 0.005), (t3, x, 0.005), (t2, x, 0.005), (t, x, 0.02), (t, x[:, 0], 0.005)]


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**16))
def test_kept_bounds_give_the_fresh_signal(seed: int) -> None:
    cases = _cases(seed)
    assert _mismatches(cases) == []
    for t, x, w in cases:
        got = sustained(t, x, w)
        want = np.stack([window_mean(t, x[:, m], w) for m in range(2)], axis=1) \
            if x.ndim == 2 else window_mean(t, x, w)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_planted_comparison_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(statistics, "_same_times", lambda a, b: a.shape == b.shape)
    assert 1 in _mismatches(_cases(0))
