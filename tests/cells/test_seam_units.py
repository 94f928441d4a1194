"""A seam's ``points_mm`` are millimetres: a seam typed in metres (0.4 for 400 mm) is refused
when its points are read, with one line naming the key and what the points would be in mm,
instead of a 0.4 mm weld that fails later as "unreachable" or passes unnoticed. Specification,
on generated lines, arcs and polylines: every seam at least 1 mm long through its points (the
length computed here from the points) is read as its points / 1000; the same seam typed in
metres, when that makes it shorter than 1 mm, is refused naming ``points_mm``. A planted
fault (the check skipped) is caught by the same oracle."""

from __future__ import annotations

import math
from unittest import mock

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from sim.cells.cellfile import seams
from sim.cells.cellfile.schema import SeamBlock
from sim.errors import CellError

COORD = st.floats(-900.0, 900.0).map(lambda v: round(v, 3))
POINT = st.tuples(COORD, COORD, COORD).map(list)
KIND_POINTS = st.one_of(
    st.tuples(st.just("line"), st.lists(POINT, min_size=2, max_size=2)),
    st.tuples(st.just("arc"), st.lists(POINT, min_size=3, max_size=3)),
    st.tuples(st.just("polyline"), st.lists(POINT, min_size=2, max_size=6)))


def _block(kind: str, points: list[list[float]]) -> SeamBlock:
    return SeamBlock(name="bead", object="plate", kind=kind, points_mm=points, normal=[0, 0, 1])


def _length_mm(points: list[list[float]]) -> float:
    return sum(math.dist(a, b) for a, b in zip(points[:-1], points[1:], strict=True))


def _verdict(kind: str, points: list[list[float]]) -> str:
    """"read" with the points in m, or the refusal's line."""
    try:
        got = seams.seam_points(_block(kind, points), "c.toml: seams[0]")
    except CellError as exc:
        return str(exc)
    assert np.array_equal(got, np.asarray(points, dtype=float) * 1e-3)
    return "read"


@settings(max_examples=80, deadline=None)
@given(kp=KIND_POINTS)
def test_a_seam_in_millimetres_is_read_and_one_typed_in_metres_refused(kp):
    kind, points = kp
    length = _length_mm(points)
    assume(length >= 1.01)  # clear of the bound by more than the points' rounding
    assert _verdict(kind, points) == "read"
    in_metres = [[round(v / 1000.0, 6) for v in p] for p in points]
    if _length_mm(in_metres) < 0.99:
        line = _verdict(kind, in_metres)
        assert line.startswith("c.toml: seams[0].points_mm: the seam is ") and "metres" in line
        assert "\n" not in line


def test_a_seam_shorter_than_a_millimetre_names_its_points_in_mm():
    with pytest.raises(CellError, match=r"points_mm: the seam is 0\.5 mm long .*\(\[0\.1, 0\.0, "
                                        r"0\.0\] would be \[100\.0, 0\.0, 0\.0\] mm"):
        seams.seam_points(_block("line", [[0.1, 0.0, 0.0], [0.1, 0.5, 0.0]]), "c.toml: seams[0]")


def test_a_short_seam_in_clear_millimetres_is_not_told_it_is_in_metres():
    with pytest.raises(CellError, match=r"the seam is 0\.5 mm long .*object's frame$"):
        seams.seam_points(_block("line", [[100.0, 50.0, 0.0], [100.0, 50.5, 0.0]]), "seams[0]")


def test_coinciding_points_are_left_to_the_seams_own_message():
    assert _verdict("line", [[100.0, 50.0, 0.0], [100.0, 50.0, 0.0]]) == "read"


def test_planted_fault_the_check_skipped_is_caught():
    with mock.patch.object(seams, "MIN_SEAM_MM", 0.0):
        assert _verdict("line", [[0.04, 0.07, 0.01], [0.16, 0.07, 0.01]]) == "read"
    assert _verdict("line", [[0.04, 0.07, 0.01], [0.16, 0.07, 0.01]]) != "read"
