"""Smooth start/stop time law s(t) (planners.profiles): the part seed 003 leaves out.

Checks against independent computations: numerical quadrature and finite differences of the
ramp polynomials, finite differences of s(t), dense-grid maxima for the peak figures.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from planners.errors import PlannerError
from planners.profiles import (
    RAMP_SHAPES,
    InvalidProfileError,
    MoveTooShortError,
    SpeedProfile,
    smoothstep,
)

SHAPES = sorted(RAMP_SHAPES)


@pytest.mark.parametrize("shape", SHAPES)
def test_smoothstep_end_conditions(shape: str) -> None:
    """h(0)=0, h(1)=1, h'=h''=0 at both ends (finite differences), integral 1/2 (quad)."""
    h = lambda x: float(smoothstep(x, shape))  # noqa: E731
    assert h(0.0) == 0.0 and h(1.0) == pytest.approx(1.0, abs=1e-15)
    e = 1e-4
    for x0 in (0.0, 1.0):
        # one-sided differences into [0, 1]
        sgn = 1.0 if x0 == 0.0 else -1.0
        d1 = (h(x0 + sgn * e) - h(x0)) / e
        d2 = (h(x0 + 2 * sgn * e) - 2 * h(x0 + sgn * e) + h(x0)) / e**2
        assert abs(d1) < 1e-6 and abs(d2) < 1e-2
    assert quad(h, 0.0, 1.0)[0] == pytest.approx(0.5, abs=1e-14)
    x = np.linspace(0, 1, 2001)
    assert np.all(np.diff(smoothstep(x, shape)) >= 0)   # monotone speed ramp


@pytest.mark.parametrize("shape", SHAPES)
def test_profile_rest_to_rest_and_derivatives(shape: str) -> None:
    L, v, T = 0.8, 0.25, 0.4
    prof = SpeedProfile(L, v, ramp_time=T, shape=shape)
    assert prof.duration == pytest.approx(L / v + T)
    s, sd, sdd, sddd = prof.evaluate(np.array([0.0, prof.duration]))
    assert s[0] == 0.0 and s[1] == L
    assert np.all(sd == 0.0) and np.all(sdd == 0.0) and np.all(sddd == 0.0)
    # finite differences of s, sd, sdd agree with sd, sdd, sddd
    t = np.linspace(1e-3, prof.duration - 1e-3, 997)
    h = 1e-5
    sp, sdp, sddp, _ = prof.evaluate(t + h)
    sm, sdm, sddm, _ = prof.evaluate(t - h)
    s, sd, sdd, sddd = prof.evaluate(t)
    assert np.max(np.abs((sp - sm) / (2 * h) - sd)) < 1e-8
    assert np.max(np.abs((sdp - sdm) / (2 * h) - sdd)) < 1e-6
    assert np.max(np.abs((sddp - sddm) / (2 * h) - sddd)) < 1e-4 * prof.peak_jerk
    assert np.all(np.diff(s) > 0)
    # constant speed strictly between the ramps
    mid = (t > T) & (t < prof.duration - T)
    assert np.all(sd[mid] == v) and np.all(sdd[mid] == 0.0)


@pytest.mark.parametrize("shape", SHAPES)
def test_profile_continuity_at_ramp_joints(shape: str) -> None:
    """s, s', s'', s''' continuous where the ramps meet the constant-speed part."""
    prof = SpeedProfile(1.0, 0.5, ramp_time=0.3, shape=shape)
    e = 1e-9
    for tj in (0.3, prof.duration - 0.3):
        left = np.array(prof.evaluate(np.array([tj - e])))[:, 0]
        right = np.array(prof.evaluate(np.array([tj + e])))[:, 0]
        scale = np.array([1.0, 0.5, prof.peak_acceleration, prof.peak_jerk])
        assert np.all(np.abs(left - right) < 1e-6 * scale)


@pytest.mark.parametrize("shape", SHAPES)
def test_peak_figures_and_acceleration_limit(shape: str) -> None:
    prof = SpeedProfile.from_max_acceleration(2.0, 0.6, 3.0, shape=shape)
    t = np.linspace(0, prof.duration, 200001)
    _, _, sdd, sddd = prof.evaluate(t)
    assert np.max(np.abs(sdd)) == pytest.approx(3.0, rel=1e-6)
    assert prof.peak_acceleration == pytest.approx(3.0, rel=1e-12)
    assert np.max(np.abs(sddd)) == pytest.approx(prof.peak_jerk, rel=1e-6)


def test_constant_speed_fraction_measured() -> None:
    L, v, T = 1.0, 0.5, 0.4
    prof = SpeedProfile(L, v, ramp_time=T)
    t = np.linspace(0, prof.duration, 400001)
    s, sd, _, _ = prof.evaluate(t)
    const = sd == v
    share = prof.constant_speed_fraction
    # measured on the grid: time at v / duration, and the length run at v / L
    assert share.time == pytest.approx(np.mean(const), abs=1e-4)
    run = prof.evaluate(np.array([prof.duration - T]))[0][0] - prof.evaluate(np.array([T]))[0][0]
    assert share.length == pytest.approx(run / L, rel=1e-12)
    assert share.length == pytest.approx(1 - v * T / L)


def test_bare_constant_speed_law() -> None:
    """ramp_time = 0 is seed 003's law s = v t."""
    prof = SpeedProfile(0.3, 0.1, ramp_time=0.0)
    t = np.linspace(0, 3.0, 31)
    s, sd, sdd, _ = prof.evaluate(t)
    assert np.allclose(s, 0.1 * t, atol=1e-15) and np.all(sd == 0.1) and np.all(sdd == 0)
    assert prof.constant_speed_fraction.time == 1.0


def test_times_outside_are_clamped() -> None:
    prof = SpeedProfile(1.0, 1.0, ramp_time=0.2)
    s, sd, _, _ = prof.evaluate(np.array([-1.0, 5.0]))
    assert s.tolist() == [0.0, 1.0] and sd.tolist() == [0.0, 0.0]


def test_move_too_short_says_how_short() -> None:
    with pytest.raises(MoveTooShortError, match=r"length: .*3 mm.*need.*5 mm") as e:
        SpeedProfile(0.003, 0.05, ramp_time=0.1)
    assert "\n" not in str(e.value)
    assert isinstance(e.value, PlannerError)
    SpeedProfile(0.005, 0.05, ramp_time=0.1)   # exactly long enough: no constant part
    assert SpeedProfile(0.005, 0.05, ramp_time=0.1).constant_speed_fraction.length == pytest.approx(0, abs=1e-12)


@pytest.mark.parametrize("kwargs, field", [
    (dict(length=1.0, speed=0.0), "speed"),
    (dict(length=1.0, speed=-1.0), "speed"),
    (dict(length=1.0, speed=float("nan")), "speed"),
    (dict(length=0.0, speed=1.0), "length"),
    (dict(length=1.0, speed=1.0, ramp_time=-0.1), "ramp_time"),
    (dict(length=1.0, speed=1.0, ramp_time=float("inf")), "ramp_time"),
    (dict(length=1.0, speed=1.0, shape="cubic"), "ramp_shape"),
])
def test_bad_profile_inputs(kwargs: dict, field: str) -> None:
    with pytest.raises(InvalidProfileError, match=f"^{field}:") as e:
        SpeedProfile(**kwargs)
    assert "\n" not in str(e.value)


def test_unknown_shape_lists_valid() -> None:
    with pytest.raises(InvalidProfileError, match="quintic, septic"):
        SpeedProfile(1.0, 1.0, shape="cubic")


def test_bad_max_acceleration() -> None:
    with pytest.raises(InvalidProfileError, match="^max_acceleration:"):
        SpeedProfile.from_max_acceleration(1.0, 1.0, 0.0)
