"""``corner_torch_excess_deg`` (:func:`sim.simulation.seam_measure.corner_torch_excess`) on
generated corner turns: zero for any steady turn from one leg's torch axis to the next (a
rotation about one axis, whatever that axis), and exactly the overshoot for a torch swung back
past the first leg's axis in the plane of the turn. The oracle is the rotation written here
(Rodrigues' formula), not the planner's corner law."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.simulation.seam_measure import corner_torch_excess

CORNER_S = 0.05  # the corner's arc length on the two-leg seam below, m
ZONE = (0.045, 0.055)


def rotate(v: np.ndarray, k: np.ndarray, angle: float) -> np.ndarray:
    """``v`` turned by ``angle`` (rad) about unit axis ``k`` (Rodrigues)."""
    return (v * math.cos(angle) + np.cross(k, v) * math.sin(angle)
            + k * (k @ v) * (1.0 - math.cos(angle)))


class TwoLegs:
    """A seam stand-in: torch axis ``a1`` before the corner, ``a2`` after it."""

    def __init__(self, a1: np.ndarray, a2: np.ndarray) -> None:
        self.a1, self.a2 = a1, a2

    def length(self) -> float:
        return 2 * CORNER_S

    def torch_axis(self, s: float) -> np.ndarray:
        return self.a1 if s <= CORNER_S else self.a2


def unit_vectors() -> st.SearchStrategy[np.ndarray]:
    return st.tuples(*[st.floats(-1.0, 1.0)] * 3).map(np.array).filter(
        lambda v: np.linalg.norm(v) > 0.1).map(lambda v: v / np.linalg.norm(v))


@settings(max_examples=60, deadline=None)
@given(a1=unit_vectors(), k=unit_vectors(), turn_deg=st.floats(1.0, 170.0),
       n=st.integers(3, 40))
def test_a_steady_turn_about_any_axis_swings_nowhere(a1, k, turn_deg, n):
    a2 = rotate(a1, k, math.radians(turn_deg))
    lam = np.linspace(0.0, 1.0, n)
    a = np.array([rotate(a1, k, x * math.radians(turn_deg)) for x in lam])
    s = np.linspace(*ZONE, n)
    assert corner_torch_excess(a, s, TwoLegs(a1, a2), [ZONE]) <= 1e-7


@settings(max_examples=60, deadline=None)
@given(a1=unit_vectors(), other=unit_vectors(), turn_deg=st.floats(1.0, 150.0),
       back_deg=st.floats(0.5, 25.0))
def test_a_torch_swung_back_past_the_first_leg_shows_its_swing(a1, other, turn_deg, back_deg):
    k = np.cross(a1, other)
    if np.linalg.norm(k) < 0.1:
        k = np.cross(a1, [1.0, 0.0, 0.0] if abs(a1[0]) < 0.9 else [0.0, 1.0, 0.0])
    k /= np.linalg.norm(k)  # perpendicular to a1: the turn stays in one plane
    a2 = rotate(a1, k, math.radians(turn_deg))
    a = np.array([a1, rotate(a1, k, -math.radians(back_deg)), a2])
    s = np.array([ZONE[0], CORNER_S, ZONE[1]])
    assert corner_torch_excess(a, s, TwoLegs(a1, a2), [ZONE]) == pytest.approx(back_deg,
                                                                                abs=1e-6)
    # the same swing outside the zone is not the corner's (torch_angle judges it there)
    outside = np.array([0.01, 0.02, ZONE[1]])
    assert corner_torch_excess(a, outside, TwoLegs(a1, a2), [ZONE]) <= 1e-7
    # no sample in the zone: no figure
    assert corner_torch_excess(a, np.array([0.005, 0.015, 0.03]), TwoLegs(a1, a2), [ZONE]) is None
