""":func:`sim.analysis.statistics.sustained` interpolates each window's ends itself, from the
sample before the end and the slope to the next one (issue 29: ``np.interp`` per column was a
third of its time). Specification: the sustained signal is, bit for bit, the one whose ends
``np.interp`` gives (the formula before, written in this test): on generated records with
uniform and uneven sampling, windows whose ends fall on samples (a multiple of the sampling
step) and between them, signed zeros, and values that are not finite (``np.interp``'s own
fallbacks). A planted fault (an end interpolated from the wrong sample) is caught."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.analysis import statistics
from sim.analysis.statistics import sustained


def _with_interp(t: np.ndarray, x: np.ndarray, w: float) -> np.ndarray:
    """The sustained signal with ``np.interp`` at the window ends (the formula before)."""
    flat = x.reshape(t.size, -1)
    c = np.concatenate([np.zeros((1, flat.shape[1])),
                        np.cumsum(0.5 * (flat[1:] + flat[:-1]) * np.diff(t)[:, None], axis=0)])
    lo = np.maximum(t - 0.5 * w, t[0])
    hi = np.minimum(t + 0.5 * w, t[-1])

    def integral_to(s: np.ndarray) -> np.ndarray:
        k = np.clip(np.searchsorted(t, s, side="right") - 1, 0, t.size - 2)
        half = (s - t[k])[:, None] * 0.5
        xs = np.stack([np.interp(s, t, flat[:, m]) for m in range(flat.shape[1])], axis=1)
        return c[k] + half * (flat[k] + xs)

    width = hi - lo
    mean = integral_to(hi) - integral_to(lo)
    out = flat.copy()
    inside = width > 0.0
    out[inside] = mean[inside] / width[inside, None]
    return out.reshape(x.shape)


def _record(seed: int, n: int, uniform: bool, special: bool) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = (np.arange(n) * 1e-3 if uniform else np.cumsum(rng.uniform(0.3e-3, 2e-3, n))) + 0.25
    x = rng.normal(size=(n, 3)) * np.array([1.0, 1e-3, 50.0])
    x[rng.integers(0, n, 5), 0] = -0.0
    x[: n // 4, 1] = 0.0  # a joint at rest, then moving
    if special:
        x[rng.integers(0, n), 2] = np.inf
        x[rng.integers(0, n), 2] = -np.inf
        x[rng.integers(0, n), 1] = np.nan
    return t, x


def _differs(seed: int, n: int, uniform: bool, special: bool, steps: int) -> bool:
    t, x = _record(seed, n, uniform, special)
    w = steps * 1e-3 if uniform else steps * 0.77e-3
    statistics._WINDOWS.clear()
    with np.errstate(invalid="ignore"):  # inf - inf in the record's non-finite values
        got = sustained(t, x, w)
        want = _with_interp(t, x, w)
        one = sustained(t, x[:, 0], w)  # a single column, as sizing passes it
        return (got.tobytes() != want.tobytes()
                or one.tobytes() != _with_interp(t, x[:, 0], w).tobytes())


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), n=st.integers(3, 400), uniform=st.booleans(),
       special=st.booleans(), steps=st.integers(1, 60))
def test_the_ends_are_np_interps_bit_for_bit(seed: int, n: int, uniform: bool, special: bool,
                                             steps: int) -> None:
    assert not _differs(seed, n, uniform, special, steps)


def test_a_long_record_at_the_sizing_window() -> None:
    """82 s at 1 kHz (the weld plate's record) with the sizing's 50 ms window and others."""
    for steps in (50, 100, 7):
        assert not _differs(3, 82_593, True, False, steps)


def test_planted_end_from_the_wrong_sample_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = statistics._windows

    def shifted(t: np.ndarray, window: float):  # type: ignore[no-untyped-def]
        lo, hi, *rest = real(t, window)
        s, k, half, ds, at_k, at_next = hi
        k = np.maximum(k - 1, 0)  # the sample before the right one
        return (lo, (s, k, half, ds, at_k, at_next), *rest)

    monkeypatch.setattr(statistics, "_windows", shifted)
    assert any(_differs(seed, 200, uniform, False, 5) for seed in range(3)
               for uniform in (True, False))
