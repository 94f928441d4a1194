""":meth:`sim.cells.seam.Seam.path_row`: the tool point, tangent and torch axis at an arc
length, each computed once (issue 29: the tool-point path of a seam sampled every millimetre
computed the torch axis twice and the tangent three times per sample). Specification, on
generated lines, arcs and polylines with generated torch angles, sides and stand-offs: the
three values are :meth:`~Seam.tcp_point`, :meth:`~Seam.tangent` and :meth:`~Seam.torch_axis`,
bit for bit, at generated arc lengths and at the ends; and the tool-point path built from them
(:class:`~sim.simulation.seam_measure.ToolPointPath`) is the one built from those three
methods. A planted stand-off of the wrong sign is caught."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.cells import seam as seam_module
from sim.cells.seam import Seam
from sim.simulation import seam_measure
from sim.simulation.seam_measure import ToolPointPath


@st.composite
def seams(draw: st.DrawFn) -> Seam:
    kind = draw(st.sampled_from(["line", "arc", "polyline"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    if kind == "arc":
        r = rng.uniform(0.05, 0.6)
        ang = np.sort(rng.uniform(0.0, 3.0, 3))
        ang[1] = 0.5 * (ang[0] + ang[2])
        ang[2] = ang[0] + max(ang[2] - ang[0], 0.3)
        ang[1] = 0.5 * (ang[0] + ang[2])
        pts = np.column_stack([r * np.cos(ang), r * np.sin(ang), np.full(3, rng.uniform(0, 1))])
    else:
        n = 2 if kind == "line" else int(rng.integers(3, 6))
        steps = rng.uniform(0.05, 0.3, (n - 1, 2)) * rng.choice([-1, 1], (n - 1, 2))
        xy = np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])
        pts = np.column_stack([xy, np.full(n, rng.uniform(0, 1))])
    return Seam(draw(st.sampled_from(["s1", "seam"])), kind, pts, None,
                draw(st.floats(-60.0, 60.0)), draw(st.floats(-30.0, 30.0)),
                surface_normal=[0.0, 0.0, 1.0], torch_side=draw(st.sampled_from([1, -1])),
                standoff_m=draw(st.sampled_from([0.0, 0.01, 0.0153])))


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def _rows_differ(seam: Seam, fractions: list[float]) -> bool:
    for seg in seam.segments():
        L = seg.length()
        for s in [0.0, L, *(f * L for f in fractions)]:
            got = seg.path_row(s)
            want = (seg.tcp_point(s), seg.tangent(s), seg.torch_axis(s))
            if not all(_same(g, w) for g, w in zip(got, want, strict=True)):
                return True
    return False


@settings(max_examples=40, deadline=None)
@given(seam=seams(), fractions=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=8))
def test_path_row_is_the_three_methods_bit_for_bit(seam: Seam, fractions: list[float]) -> None:
    assert not _rows_differ(seam, fractions)


@settings(max_examples=10, deadline=None)
@given(seam=seams())
def test_the_tool_point_path_is_built_from_the_three_methods(seam: Seam) -> None:
    got = ToolPointPath._make(seam)
    s0, parts = 0.0, []
    for seg in seam.segments():  # the path before: each value from its own method
        n = len(ToolPointPath._make(seg).s)
        ss = np.linspace(0.0, float(seg.length()), n)
        parts += [(s0 + x, seg.tcp_point(x), seg.tangent(x), seg.torch_axis(x)) for x in ss]
        s0 += float(seg.length())
    s, point, tangent, axis = (np.array(v) for v in zip(*parts, strict=True))
    for g, w in ((got.s, s), (got.point, point), (got.tangent, tangent), (got.axis, axis)):
        assert _same(g, w)


def test_planted_standoff_sign_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = Seam.path_row

    def wrong_sign(self: Seam, s: float):  # type: ignore[no-untyped-def]
        p, t, a = real(self, s)
        return p + 2.0 * self.standoff_m * a, t, a

    monkeypatch.setattr(seam_module.Seam, "path_row", wrong_sign)
    seam = Seam("x", "line", [[0, 0, 0], [0.2, 0, 0]], None, 30.0, 5.0,
                surface_normal=[0, 0, 1], standoff_m=0.01)
    assert _rows_differ(seam, [0.5])
    seam_measure.clear_caches()


_components = st.one_of(st.floats(allow_nan=False, allow_infinity=False, width=64),
                        st.sampled_from([0.0, -0.0, 1.0, -1.0, 1e-310, 1e300]))


@settings(max_examples=300, deadline=None)
@given(a=st.lists(_components, min_size=3, max_size=3),
       b=st.lists(_components, min_size=3, max_size=3))
def test_the_seams_cross_product_is_numpys_bit_for_bit(a: list[float], b: list[float]) -> None:
    """The torch axis's cross product (``_cross3``, in Python floats: issue 29, a seam's path
    of thousands of rows) gives ``np.cross``'s bits, signed zeros, overflow and
    subnormals included."""
    x, y = np.array(a), np.array(b)
    with np.errstate(all="ignore"):
        want = np.cross(x, y)
    assert _same(seam_module._cross3(x, y), want)


def test_planted_cross_product_order_is_caught() -> None:
    x, y = np.array([0.3, -1.2, 2.0]), np.array([1.5, 0.25, -0.7])
    assert not _same(seam_module._cross3(y, x), np.cross(x, y))


@st.composite
def tilted_arcs(draw: st.DrawFn) -> Seam:
    """Arcs in a drawn plane, with a drawn surface normal (not along the plane's normal)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    r = rng.uniform(0.02, 1.5)
    ang = np.cumsum(np.r_[rng.uniform(-3, 3), rng.uniform(0.1, 3.0, 2)])
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    pts = rng.uniform(-1, 1, 3) + (q[:, :2] @ np.vstack([r * np.cos(ang), r * np.sin(ang)])).T
    normal = q[:, 2] + rng.uniform(-0.4, 0.4, 3)
    return Seam("arc", "arc", pts, None, draw(st.floats(-80.0, 80.0)),
                draw(st.floats(-45.0, 45.0)), surface_normal=normal,
                torch_side=draw(st.sampled_from([1, -1])),
                standoff_m=draw(st.sampled_from([0.0, 0.004, 0.0153])))


def _stacked_rows(seam: Seam, s: np.ndarray) -> tuple[np.ndarray, ...]:
    return tuple(np.array(v) for v in zip(*(seam.path_row(float(x)) for x in s), strict=True))


@settings(max_examples=40, deadline=None)
@given(seam=st.one_of(seams(), tilted_arcs()),
       fractions=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=50))
def test_path_rows_are_path_row_at_each_arc_length_bit_for_bit(seam: Seam,
                                                               fractions: list[float]) -> None:
    """:meth:`Seam.path_rows` (issue 29: an arc's rows as arrays, a path of thousands of rows
    in a millisecond or two) gives each row :meth:`Seam.path_row` gives, bit for bit."""
    for seg in seam.segments():
        s = np.array([0.0, *fractions, 1.0]) * seg.length()
        got = seg.path_rows(s)
        for g, w in zip(got, _stacked_rows(seg, s), strict=True):
            assert _same(g, w)


def test_planted_arc_row_fault_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """A fault planted in the arrays' torch axis (the work angle's sine dropped) is caught by
    the row-by-row oracle."""
    seam = Seam("a", "arc", [[0.3, 0, 0], [0, 0.3, 0], [-0.3, 0, 0]], None, 40.0, 10.0,
                surface_normal=[0, 0, 1])
    s = np.linspace(0.0, seam.length(), 17)
    real_deg2rad = np.deg2rad

    def off(x):  # type: ignore[no-untyped-def]
        return real_deg2rad(x) * (1.0 + 1e-12)

    monkeypatch.setattr(seam_module.np, "deg2rad", off)
    got = seam.path_rows(s)
    monkeypatch.setattr(seam_module.np, "deg2rad", real_deg2rad)
    assert not _same(got[2], _stacked_rows(seam, s)[2])


def test_a_surface_normal_along_an_arc_is_refused_as_row_by_row() -> None:
    """An arc whose surface normal runs along the seam somewhere (a normal in its plane):
    the arrays refuse it with the row-by-row message, naming where."""
    from sim.errors import CellsimError

    seam = Seam("a", "arc", [[0.3, 0, 0], [0, 0.3, 0], [-0.3, 0, 0]], None, 40.0, 10.0,
                surface_normal=[1.0, 0.0, 0.0])
    s = np.linspace(0.0, seam.length(), 9)
    with pytest.raises(CellsimError) as rows:
        seam.path_rows(s)
    with pytest.raises(CellsimError) as row:
        _stacked_rows(seam, s)
    assert str(rows.value) == str(row.value) and "surface normal runs along" in str(row.value)
