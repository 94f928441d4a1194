""":func:`sim.analysis.statistics.exact_sum`, the exactly rounded sum the time integrals use
(issue 29: faster than ``math.fsum`` on long records). Specification: ``math.fsum``'s result
bit for bit (the oracle), on values of any magnitudes, with cancellations, ties, subnormals and
signed zeros; a planted fault (the mantissas' low halves dropped) is caught."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from sim.analysis import statistics
from sim.analysis.statistics import exact_sum

FINITE = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300)


def _bits(v: float) -> int:
    return int(np.float64(v).view(np.int64))


def _special(seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    n = 200
    x = rng.normal(size=n)
    return [x, x * 10.0 ** rng.integers(-300, 290, n),
            np.concatenate([x, -x[::-1], [1e-310, 5e-324, -2.5e-320]]),
            np.concatenate([x * 1e16, x, [0.5, 1e16]]),
            np.array([1.0, 2.0 ** -53] * 7 + [2.0 ** -53 * (1 + 2 ** -52)]),  # ties
            np.array([1.0, 2.0 ** -53] * 8),
            np.array([-0.0, -0.0]), np.array([0.0, -0.0]), np.array([5e-324, -5e-324]),
            np.array([1e300, 1e300, -1e300])]


def _mismatches(seeds: range) -> list[str]:
    bad = []
    for seed in seeds:
        for k, x in enumerate(_special(seed)):
            if _bits(exact_sum(x)) != _bits(math.fsum(x.tolist())):
                bad.append(f"seed {seed} case {k}")
    return bad


def test_special_cases_are_fsum() -> None:
    assert _mismatches(range(5)) == []


@settings(max_examples=60, deadline=None)
@given(x=arrays(np.float64, st.integers(1, 60), elements=FINITE))
def test_generated_values_are_fsum(x: np.ndarray) -> None:
    assert _bits(exact_sum(x)) == _bits(math.fsum(x.tolist()))


def test_a_long_record_is_fsum() -> None:
    t = np.cumsum(np.full(100_000, 5e-4))
    x = np.sin(3.0 * t) * np.exp(-t) + 1e-9 * np.cos(t)
    assert _bits(exact_sum(x)) == _bits(math.fsum(x.tolist()))
    assert _bits(exact_sum(x * 1e-310)) == _bits(math.fsum((x * 1e-310).tolist()))


def test_planted_low_halves_dropped_are_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = np.bincount

    def no_low(ex: np.ndarray, weights: np.ndarray, minlength: int) -> np.ndarray:
        if no_low.calls % 2:  # the second call of each sum: the low halves
            weights = np.zeros_like(weights)
        no_low.calls += 1
        return real(ex, weights=weights, minlength=minlength)

    no_low.calls = 0
    monkeypatch.setattr(statistics.np, "bincount", no_low)
    assert _mismatches(range(1)) != []


def test_one_exponent_group_at_its_bound_is_fsum() -> None:
    """2**17 values of one exponent with their largest mantissas: each half's group sum is at
    its largest (the split's exactness bound), positive so nothing cancels."""
    rng = np.random.default_rng(7)
    mant = rng.integers(2**52 - 2**30, 2**52, 1 << 17)
    x = (2.0**52 + mant.astype(np.float64)) * 2.0**-52  # in [1, 2)
    assert _bits(exact_sum(x)) == _bits(math.fsum(x.tolist()))
    y = np.concatenate([x * 2.0**993, -x[:1000] * 2.0**-1000])  # just below the fsum limit
    assert _bits(exact_sum(y)) == _bits(math.fsum(y.tolist()))


def test_a_column_with_an_inf_or_a_nan_is_numpys_sum() -> None:
    x = np.array([1.0, np.inf, 2.0])
    assert statistics._sum(x) == np.inf
    assert math.isnan(statistics._sum(np.array([1.0, np.nan])))
    with np.errstate(invalid="ignore"):  # numpy's own inf - inf
        assert math.isnan(statistics._sum(np.array([np.inf, -np.inf])))
    t = np.array([0.0, 1.0, 2.0])
    assert statistics.time_integral(t, x) == np.inf
