"""The nearest point on a seam's tool-point path (issue 29: a sweep variant measures its seams
faster, with the same bits). Specification of :func:`seam_measure.nearest_on_polyline`: the
chords on either side of the ``k`` nearest vertices are tried in order (nearest vertex first,
the chord before it first); the answer is the first chord at the least distance, its fraction
and distance; a NaN distance never wins. The oracle tries every chord in that order, one at a
time, as the function was first written; the answers must be equal bit for bit on generated
paths: finely sampled arcs (the tries of a point fall in a run of chords), corners, closed
paths, repeated vertices, points on a grid that make exact ties, distances that overflow. A planted
shortcut that lets the lowest chord win a tie is caught."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from sim.simulation import seam_measure
from sim.simulation.seam_measure import nearest_on_polyline

FAST = settings(max_examples=60, deadline=None, derandomize=True, database=None)


def tried_in_order(p: NDArray[np.float64], pts: NDArray[np.float64], k: int = 8
                   ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
    """The oracle: every try, one at a time, a strictly smaller distance replacing the best."""
    k = min(k, len(pts))
    _, idx = cKDTree(pts).query(p, k=k)
    idx = np.asarray(idx).reshape(len(p), k)
    best_d = np.full(len(p), np.inf)
    best_i = np.zeros(len(p), dtype=np.intp)
    best_u = np.zeros(len(p))
    for j in range(k):
        for off in (-1, 0):
            i0 = np.clip(idx[:, j] + off, 0, len(pts) - 2)
            a, ab = pts[i0], pts[i0 + 1] - pts[i0]
            u = np.clip(np.einsum("ij,ij->i", p - a, ab)
                        / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-30), 0.0, 1.0)
            d = np.linalg.norm(p - (a + u[:, None] * ab), axis=1)
            better = d < best_d
            best_d = np.where(better, d, best_d)
            best_i = np.where(better, i0, best_i)
            best_u = np.where(better, u, best_u)
    return best_i, best_u, best_d


def assert_same_bits(got: tuple[NDArray, ...], want: tuple[NDArray, ...]) -> None:
    for g, w, name in zip(got, want, ("chord", "fraction", "distance"), strict=True):
        assert g.dtype == w.dtype and g.shape == w.shape, name
        assert g.tobytes() == w.tobytes(), (name, np.flatnonzero(g != w)[:5])


def _arc(radius: float, turn: float, n: int) -> NDArray[np.float64]:
    a = np.linspace(0.0, turn, n)
    return np.stack([radius * np.cos(a), radius * np.sin(a), 0.01 * a], axis=1)


@FAST
@given(radius=st.floats(0.05, 2.0), turn=st.floats(0.1, 2 * np.pi), n=st.integers(2, 400),
       k=st.integers(1, 10), seed=st.integers(0, 2**32 - 1), spread=st.floats(1e-5, 0.3))
def test_sampled_arcs_and_closed_paths(radius: float, turn: float, n: int, k: int, seed: int,
                                       spread: float) -> None:
    pts = _arc(radius, turn, n)
    if turn > 6.2:  # a full circle: the path ends where it starts
        pts[-1] = pts[0]
    rng = np.random.default_rng(seed)
    p = pts[rng.integers(0, n, 300)] + rng.normal(scale=spread * radius, size=(300, 3))
    assert_same_bits(nearest_on_polyline(p, pts, k), tried_in_order(p, pts, k))


@FAST
@given(verts=st.lists(st.tuples(*[st.integers(-3, 3)] * 3), min_size=2, max_size=12),
       k=st.integers(1, 12), seed=st.integers(0, 2**32 - 1))
def test_grid_paths_with_ties_corners_and_repeated_vertices(verts: list[tuple[int, ...]],
                                                            k: int, seed: int) -> None:
    pts = np.asarray(verts, dtype=float)
    rng = np.random.default_rng(seed)
    # half-grid points: equidistant from several chords, on vertices, on chords
    p = rng.integers(-8, 9, size=(200, 3)) / 2.0
    assert_same_bits(nearest_on_polyline(p, pts, k), tried_in_order(p, pts, k))


def test_overflowing_points_and_no_points() -> None:
    pts = _arc(0.5, 1.0, 50)
    # distances that overflow to inf (no chord below infinity) or to NaN (inf - inf)
    p = np.array([[0.5, 0.0, 0.0], [1e200, 0.0, 0.0], [1e300, -1e300, 1e300], [0.4, 0.3, 0.0]])
    with np.errstate(over="ignore", invalid="ignore"):
        assert_same_bits(nearest_on_polyline(p, pts), tried_in_order(p, pts))
    assert_same_bits(nearest_on_polyline(np.zeros((0, 3)), pts),
                     tried_in_order(np.zeros((0, 3)), pts))


TIE_PATH = np.array([[-1.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 2.0, 0.0], [0.0, 2.0, 0.0]])
TIE_POINT = np.array([[1.0, 1.0, 0.0]])  # 1 m from chords 0 and 2; vertex 3 is nearest


def test_a_tie_goes_to_the_first_try() -> None:
    i, u, d = nearest_on_polyline(TIE_POINT, TIE_PATH)
    assert (i[0], u[0], d[0]) == (2, 0.75, 1.0)


def test_a_shortcut_that_breaks_ties_by_chord_index_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    real = seam_measure._nearest_in_runs

    def lowest_chord_wins(*args: object) -> object:
        i, u, d, exact = real(*args)  # type: ignore[arg-type]
        return i, u, d, np.ones_like(exact)

    monkeypatch.setattr(seam_measure, "_nearest_in_runs", lowest_chord_wins)
    got = nearest_on_polyline(TIE_POINT, TIE_PATH)
    with pytest.raises(AssertionError):
        assert_same_bits(got, tried_in_order(TIE_POINT, TIE_PATH))
