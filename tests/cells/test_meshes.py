"""Meshes of cell objects (issue 31): every mesh, broken or not, is loaded in bounded work.

Specification: a mesh file with a non-finite coordinate is refused, naming the triangle; an
open mesh (a missing face) collides as its convex hull, said by a warning, without running
the convex decomposition (CoACD loops without end on an open surface); a closed concave mesh
is decomposed in a child process under a CPU budget, and a decomposition past the budget
falls back to the hull, said so; the fallback is never cached. The oracles are written here:
the hull from scipy's Qhull on the file's own vertices, the open edges counted from the
triangles.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull
from support.cell_files import make_cell, write_bracket

import sim.cells.meshes as meshes
from sim.cli import main
from sim.errors import CellError


def _bracket(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The closed concave L bracket of the cell tests, as (vertices mm, triangles)."""
    import trimesh

    write_bracket(path)
    m = trimesh.load(path, force="mesh", process=True)
    return np.asarray(m.vertices, dtype=float), np.asarray(m.faces, dtype=np.int64)


def _write(path: Path, verts: np.ndarray, faces: np.ndarray) -> Path:
    import trimesh

    trimesh.Trimesh(verts, faces, process=False).export(path)
    return path


def _same_hull(piece: np.ndarray, verts_m: np.ndarray) -> bool:
    """Whether ``piece`` spans the convex hull of ``verts_m`` (same hull volume, every point of
    either inside the other's hull)."""
    return bool(np.isclose(ConvexHull(piece).volume, ConvexHull(verts_m).volume, rtol=1e-9))


def _pieces(path: Path, **kw) -> tuple[list[np.ndarray], list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pieces = meshes.convex_pieces(path, "mm", "cell.toml: objects[0].file", **kw)
    return pieces, [str(w.message) for w in caught if issubclass(w.category,
                                                                  meshes.MeshHullWarning)]


def test_an_open_mesh_collides_as_its_hull_said_so_and_nothing_is_cached(tmp_path, monkeypatch):
    verts, faces = _bracket(tmp_path / "closed.stl")
    stl = _write(tmp_path / "open.stl", verts, faces[:-1])  # one triangle missing

    def never(*_a, **_k):  # the decomposition must not even start on an open mesh
        raise AssertionError("decomposition run on an open mesh")

    monkeypatch.setattr(meshes, "decompose_bounded", never)
    pieces, said = _pieces(stl)
    assert len(pieces) == 1 and _same_hull(pieces[0], verts * 1e-3)
    assert len(said) == 1 and "objects[0].file: open.stl: the mesh is open (3 edge(s)" in said[0]
    assert "convex hull" in said[0]
    assert list(tmp_path.glob("*.coacd-*")) == []


def test_a_non_finite_coordinate_is_refused_naming_the_triangle(tmp_path):
    verts, faces = _bracket(tmp_path / "closed.stl")
    tri = verts[faces]  # per-triangle vertices, as an STL stores them
    tri[4, 1, 2] = np.nan
    stl = _write(tmp_path / "nan.stl", tri.reshape(-1, 3), np.arange(tri.size // 3).reshape(-1, 3))
    with pytest.raises(CellError, match=r"nan\.stl: triangle 5 of \d+ has a coordinate that is "
                                        r"not finite"):
        meshes.convex_pieces(stl, "mm", "cell.toml: objects[0].file")


def test_a_decomposition_past_its_budget_falls_back_to_the_hull(tmp_path, monkeypatch):
    """The bracket takes CoACD seconds; a budget of 0.2 s of CPU stops it in the child."""
    verts, _ = _bracket(tmp_path / "b.stl")
    monkeypatch.setattr(meshes, "DECOMPOSITION_CPU_S", 0.2)
    pieces, said = _pieces(tmp_path / "b.stl")
    assert len(pieces) == 1 and _same_hull(pieces[0], verts * 1e-3)
    assert len(said) == 1 and "ran past its budget of 0.2 s of CPU" in said[0], said
    assert list(tmp_path.glob("*.coacd-*")) == []  # the next load tries again


def test_the_cli_says_so_in_one_line(tmp_path, capsys):
    """`cellsim check` of a cell whose bracket lost a triangle: one warning line naming the
    object's key and the file, no traceback."""
    scenario = make_cell(tmp_path)
    stl = tmp_path / "cells" / "parts" / "bracket.stl"
    import trimesh

    m = trimesh.load(stl, force="mesh", process=True)
    _write(stl, np.asarray(m.vertices), np.asarray(m.faces)[:-1])
    rc = main(["check", str(scenario)])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.startswith("cellsim: warning:")]
    assert rc in (0, 1) and "Traceback" not in err, err
    assert len(lines) == 1 and "objects[2].file: bracket.stl: the mesh is open" in lines[0], err


def _damage(verts: np.ndarray, faces: np.ndarray, data: st.DataObject
            ) -> tuple[np.ndarray, np.ndarray, bool]:
    """A damaged copy of a closed mesh: triangles removed, flipped or duplicated, vertices
    moved or made NaN. Returns (verts, faces, has_nan)."""
    verts, faces = verts.copy(), faces.copy()
    n_drop = data.draw(st.integers(0, 3), label="triangles removed")
    drop = data.draw(st.lists(st.integers(0, len(faces) - 1), min_size=n_drop,
                              max_size=n_drop, unique=True), label="which")
    faces = np.delete(faces, drop, axis=0)
    for k in data.draw(st.lists(st.integers(0, len(faces) - 1), max_size=3), label="flipped"):
        faces[k] = faces[k, ::-1]
    dup = data.draw(st.lists(st.integers(0, len(faces) - 1), max_size=2), label="duplicated")
    faces = np.vstack([faces, faces[dup]]) if dup else faces
    for k in data.draw(st.lists(st.integers(0, len(verts) - 1), max_size=2), label="moved"):
        verts[k] += data.draw(st.tuples(*[st.floats(-50, 50)] * 3), label="by (mm)")
    has_nan = data.draw(st.booleans(), label="a NaN vertex")
    if has_nan:
        verts[data.draw(st.integers(0, len(verts) - 1), label="nan vertex"), 0] = np.nan
    return verts, faces, has_nan


def _check_damaged(tmp_path: Path, data: st.DataObject, budget: float) -> None:
    verts, faces = _bracket(tmp_path / "closed.stl")
    v, f, has_nan = _damage(verts, faces, data)
    stl = tmp_path / "damaged.stl"
    stl.unlink(missing_ok=True)
    for c in tmp_path.glob("damaged.stl.coacd-*"):
        c.unlink()
    _write(stl, v, f)
    used = [v[np.unique(f)]]
    if has_nan and not np.all(np.isfinite(used[0])):
        with pytest.raises(CellError, match="not finite"):
            meshes.convex_pieces(stl, "mm", "w")
        return
    try:
        pieces, said = _pieces(stl)
    except CellError as exc:  # e.g. every vertex moved into a plane: one line
        assert "\n" not in str(exc)
        return
    assert pieces and all(len(p) >= 4 and np.all(np.isfinite(p)) for p in pieces)
    edges = np.sort(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    if np.any(counts == 1):  # open (the oracle counts the edges itself): the hull, said so
        assert len(pieces) == 1 and said and "open" in said[0]
        assert _same_hull(pieces[0], used[0] * 1e-3)
    # every piece lies within the hull of the file's own vertices (Qhull's facets), up to
    # CoACD's own rounding: its pieces' vertices reach a few micrometres past the hull of a
    # damaged bracket (measured: up to 3.4 um on the 0.2 m bracket with a vertex moved 35 mm,
    # 1.7e-5 of its size), so the hull is widened by 1e-4 of the vertices' extent
    eq = ConvexHull(used[0] * 1e-3).equations
    tol = 1e-4 * float(np.ptp(used[0] * 1e-3, axis=0).max())
    for p in pieces:
        assert np.all(p @ eq[:, :3].T + eq[:, 3] <= tol)


@settings(max_examples=4, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_generated_broken_meshes_load_in_bounded_work(tmp_path, monkeypatch, data):
    monkeypatch.setattr(meshes, "DECOMPOSITION_CPU_S", 1.0)
    _check_damaged(tmp_path, data, 1.0)


@pytest.mark.slow
@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_generated_broken_meshes_load_in_bounded_work_many(tmp_path, monkeypatch, data):
    monkeypatch.setattr(meshes, "DECOMPOSITION_CPU_S", 2.0)
    _check_damaged(tmp_path, data, 2.0)
