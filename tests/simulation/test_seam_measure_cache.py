"""A seam's tool-point path and its nearest-point answers are kept per process (issue 29: the
variants of a sweep's plan measure the same seams and the same reference tool points again).
Specification: whatever was asked before, every answer is the one computed afresh for that
seam and those points, bit for bit; a seam or a point that differs in one field or one bit
gets its own answer. The oracle is the uncached construction (``ToolPointPath._make``,
``_nearest``) of each seam and point set alone; a planted key that forgets a field or the
points' values is caught."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.cells.seam import Seam
from sim.simulation import seam_measure
from sim.simulation.seam_measure import ToolPointPath

UP = np.array([0.0, 0.0, 1.0])
LINE = Seam("l", "line", np.array([[0.40, -0.06, 0.20], [0.47, 0.05, 0.21]]), None, 45.0, 10.0,
            UP, torch_side=1)
ARC = Seam("a", "arc", np.array([[0.45, 0.00, 0.20], [0.44, 0.01, 0.20], [0.43, 0.00, 0.20]]),
           UP, 45.0, -8.0, UP, torch_side=-1, tool_axis=0, standoff_m=0.004)
POLY = Seam("ell", "polyline", np.array([[0.40, -0.03, 0.20], [0.46, -0.03, 0.20],
                                         [0.46, 0.02, 0.20]]), None, 45.0, 12.0, UP,
            torch_side=1, standoff_m=0.002)


def _twins(seam: Seam) -> list[Seam]:
    """The seam, and seams that differ from it in one field (or in one bit of one)."""
    pts = seam.points.copy()
    pts[-1, 0] = np.nextafter(pts[-1, 0], np.inf)
    return [seam,
            dataclasses.replace(seam, points=pts),
            dataclasses.replace(seam, torch_work_angle_deg=seam.torch_work_angle_deg + 5.0),
            dataclasses.replace(seam, torch_travel_angle_deg=-seam.torch_travel_angle_deg),
            dataclasses.replace(seam, standoff_m=seam.standoff_m + 0.003),
            dataclasses.replace(seam, torch_side=-seam.torch_side)]


def _same(a: dict | ToolPointPath, b: dict | ToolPointPath) -> bool:
    keys = ("s", "point", "tangent", "axis") if isinstance(a, ToolPointPath) else tuple(a)
    return all(np.asarray(getattr(a, k) if isinstance(a, ToolPointPath) else a[k]).tobytes()
               == np.asarray(getattr(b, k) if isinstance(b, ToolPointPath) else b[k]).tobytes()
               for k in keys)


def _mismatches(seams: list[Seam], points: list[np.ndarray]) -> list[str]:
    """Every seam's kept path and nearest answers against the uncached ones, asked in turn
    and again (the second round answered from the caches)."""
    seam_measure.clear_caches()
    fresh = [ToolPointPath._make(seam) for seam in seams]
    bad = []
    for _ in range(2):
        for k, seam in enumerate(seams):
            path = ToolPointPath.of(seam)
            if not _same(path, fresh[k]):
                bad.append(f"path of seam {k}")
            for m, p in enumerate(points):
                got = path.nearest(p)
                if not _same(got, path._nearest(p)):
                    bad.append(f"nearest of seam {k}, points {m}")
    return bad


def _points(seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    p = np.array([0.44, 0.0, 0.2]) + rng.normal(scale=0.03, size=(40, 3))
    q = p.copy()
    q[7, 1] = np.nextafter(q[7, 1], -np.inf)  # one bit of one point
    r = p.copy()
    r[7] += 0.004  # one point moved 4 mm
    return [p, q, r, p[:20]]


@pytest.fixture(autouse=True)
def fresh():
    seam_measure.clear_caches()
    yield
    seam_measure.clear_caches()


def test_kept_answers_are_the_fresh_ones() -> None:
    seams = [s for base in (LINE, ARC, POLY) for s in _twins(base)]
    assert _mismatches(seams, _points(0)) == []
    assert len(seam_measure._PATHS) == min(len(seams), seam_measure.PATH_CACHE_SIZE)


@settings(max_examples=5, deadline=None)
@given(seed=st.integers(0, 2**16), which=st.sampled_from(["l", "a", "ell"]))
def test_generated_points(seed: int, which: str) -> None:
    base = {"l": LINE, "a": ARC, "ell": POLY}[which]
    assert _mismatches(_twins(base)[:3], _points(seed)) == []


def test_callers_cannot_change_a_kept_answer() -> None:
    path = ToolPointPath.of(LINE)
    with pytest.raises(ValueError):
        path.point[0, 0] = 1.0
    p = _points(1)[0]
    first = path.nearest(p)
    first["s"][:] = -1.0  # the caller's own copy
    assert _same(path.nearest(p), path._nearest(p))


def test_planted_seam_key_without_a_field_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = seam_measure.seam_key
    monkeypatch.setattr(seam_measure, "seam_key",
                        lambda seam: real(dataclasses.replace(seam, standoff_m=0.0)))
    bad = _mismatches(_twins(ARC), _points(2))
    assert any(b.startswith("path of seam 4") for b in bad)


def test_planted_points_key_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = seam_measure._value_key
    monkeypatch.setattr(seam_measure, "_value_key",
                        lambda v: ("shape", v.shape) if isinstance(v, np.ndarray)
                        and v.ndim == 2 and v.shape[1] == 3 and v.shape[0] >= 20 else real(v))
    bad = _mismatches([LINE], _points(3))
    assert "nearest of seam 0, points 2" in bad
