"""Damaged and hostile run folders (issue 31): `cellsim render RUN_FOLDER` answers each with one
line naming the folder and the file (and its member or field), exit 2, never a traceback, and
never reads a file outside the folder: not through ``model.xml`` (every route MuJoCo resolves a
file by: meshdir, texturedir, assetdir, several <compiler> sections, height fields, skins,
textures, absolute names, ``..`` and ``\\``, symbolic links), nor through a run file that is a
symbolic link elsewhere.

The CLI runs in-process with the OpenGL video replaced by :func:`_read_like_render`, which reads
all a render reads (the model compiled by MuJoCo, the overlay's paths, the captions, the
collisions to paint) without drawing, so that a folder that loads costs milliseconds.
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import struct
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sim.cli import main
from sim.render.synthetic import write_synthetic_run
from sim.simulation import runfolder
from sim.simulation.runfolder import RunFolderError, load_run, model_file_names

#: A small tetrahedron (OBJ) and a 3x3 height field (MuJoCo's binary format).
OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
HFIELD = struct.pack("<ii", 3, 3) + np.linspace(0.0, 1.0, 9, dtype="<f4").tobytes()
FUZZ = settings(max_examples=25, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture])
FUZZ_SLOW = settings(max_examples=400, deadline=None, derandomize=True,
                     suppress_health_check=[HealthCheck.function_scoped_fixture,
                                            HealthCheck.too_slow])


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small synthetic run folder (1 s at 20 Hz), written once; tests spoil copies of it."""
    return write_synthetic_run(tmp_path_factory.mktemp("hostile") / "run", duration=1.0,
                               rate=20.0)


def _read_like_render(record, out, **_kw) -> None:
    """``write_video`` without OpenGL: what a render reads of the run, drawing nothing."""
    from sim.render.frames import CollisionPainter
    from sim.render.overlay import PathOverlay, caption_text

    model = record.load_model()
    qpos = record.get("qpos")
    if qpos.ndim != 2 or qpos.shape[1] != model.nq:
        raise RunFolderError(f"{record.where}: trajectory.npz 'qpos' has shape {qpos.shape} "
                             f"but model.xml has nq={model.nq}")
    PathOverlay(record)
    for time in np.linspace(record.t0, float(record.t[-1]), 4):
        caption_text(record, float(time))
    CollisionPainter(model, record.summary.get("collisions", ()))


@pytest.fixture(autouse=True)
def no_gl(monkeypatch: pytest.MonkeyPatch) -> list:
    """No OpenGL: the backend probe and the video are replaced; returns the runs "rendered"."""
    from sim.render import gl, video

    rendered: list = []

    def fake_video(record, out, **kw):
        _read_like_render(record, out, **kw)
        rendered.append(record)

    monkeypatch.setattr(gl, "configure_gl", lambda name=None: "egl")
    monkeypatch.setattr(video, "write_video", fake_video)
    return rendered


def _copy(base: Path, where: Path) -> Path:
    where.mkdir(parents=True, exist_ok=True)
    folder = Path(tempfile.mkdtemp(dir=where)) / "run"
    shutil.copytree(base, folder)
    return folder


def _render(folder: Path, capsys: pytest.CaptureFixture) -> tuple[int, str]:
    rc = main(["render", str(folder), "--quiet"])
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert rc in (0, 2), (rc, err)
    return rc, err


def _refused(folder: Path, capsys: pytest.CaptureFixture, *words: str) -> str:
    """Render ``folder``: exit 2, one line naming the folder and every one of ``words``."""
    rc, err = _render(folder, capsys)
    assert rc == 2 and err.count("\n") == 1 and err.startswith("cellsim: error: "), err
    assert str(folder) in err, err
    for word in words:
        assert word in err, (word, err)
    return err


# ---------------------------------------------------------------- model.xml's files
def _add(folder: Path, asset: str = "", compiler: str = "", body: str = "") -> None:
    """Add ``asset`` to model.xml's <asset>, <compiler> sections after its own, ``body`` to
    the worldbody."""
    xml = (folder / "model.xml").read_text()
    xml = xml.replace('<compiler angle="radian"/>', '<compiler angle="radian"/>' + compiler, 1)
    xml = xml.replace("<asset>", "<asset>\n" + asset, 1)
    xml = xml.replace("<worldbody>", "<worldbody>\n" + body, 1)
    (folder / "model.xml").write_text(xml)


def _secret(outside: Path) -> dict[str, Path]:
    """Valid assets outside the run folder, never read yet (access time 0)."""
    import imageio.v3 as iio

    outside.mkdir(parents=True, exist_ok=True)
    png = io.BytesIO()
    iio.imwrite(png, np.full((4, 4, 3), 200, np.uint8), extension=".png")
    files = {"obj": outside / "secret.obj", "bin": outside / "secret.bin",
             "png": outside / "secret.png", "skn": outside / "secret.skn"}
    files["obj"].write_text(OBJ)
    files["bin"].write_bytes(HFIELD)
    files["png"].write_bytes(png.getvalue())
    files["skn"].write_bytes(b"\0" * 64)
    for path in files.values():
        os.utime(path, (0, path.stat().st_mtime))
    return files


def _atime_is_kept(path: Path) -> bool:
    """Whether reading a file updates its access time here (relatime does from time 0)."""
    probe = path / "atime-probe"
    probe.write_text("x")
    os.utime(probe, (0, probe.stat().st_mtime))
    probe.read_text()
    return probe.stat().st_atime != 0


def _hfield_meshdir(f: Path, out: Path) -> None:
    # the reported bug: a height field resolved against texturedir (here t/u, so that ../..
    # stays inside) instead of meshdir (m: ../.. leaves the folder)
    (f / "m").mkdir()
    (f / "t" / "u").mkdir(parents=True)
    _add(f, '<hfield name="h" size="1 1 1 1" file="../../outside/secret.bin"/>',
         '<compiler meshdir="m" texturedir="t/u"/>')


def _hfield_assetdir(f: Path, out: Path) -> None:
    (f / "a" / "b").mkdir(parents=True)
    _add(f, '<hfield name="h" size="1 1 1 1" file="../../../outside/secret.bin"/>',
         '<compiler assetdir="a/b"/>')


def _hfield_two_compilers(f: Path, out: Path) -> None:
    # a later <compiler assetdir> overrides an earlier texturedir, and meshdir after it
    (f / "m").mkdir()
    (f / "t" / "u").mkdir(parents=True)
    _add(f, '<hfield name="h" size="1 1 1 1" file="../../outside/secret.bin"/>',
         '<compiler texturedir="t/u"/><compiler assetdir="t/u"/><compiler meshdir="m"/>')


def _texture(f: Path, out: Path) -> None:
    (f / "t").mkdir()
    _add(f, '<texture name="s" type="2d" file="../../outside/secret.png"/>',
         '<compiler texturedir="t"/>')


def _texture_cube(f: Path, out: Path) -> None:
    (f / "t").mkdir()
    _add(f, '<texture name="s" type="cube" fileup="../../outside/secret.png"/>',
         '<compiler meshdir="t" texturedir="t"/>')


def _skin(f: Path, out: Path) -> None:
    (f / "m").mkdir()
    (f / "t" / "u").mkdir(parents=True)
    _add(f, '<skin name="s" file="../../outside/secret.skn"/>',
         '<compiler meshdir="m" texturedir="t/u"/>')


def _mesh_dotdot(f: Path, out: Path) -> None:
    _add(f, '<mesh name="s" file="../outside/secret.obj"/>')


def _mesh_absolute(f: Path, out: Path) -> None:
    _add(f, f'<mesh name="s" file="{out / "secret.obj"}"/>', '<compiler meshdir="."/>')


def _mesh_backslash(f: Path, out: Path) -> None:
    _add(f, '<mesh name="s" file="..\\outside\\secret.obj"/>')


def _mesh_symlink(f: Path, out: Path) -> None:
    (f / "link.obj").symlink_to(out / "secret.obj")
    _add(f, '<mesh name="s" file="link.obj"/>')


def _mesh_symlink_dir(f: Path, out: Path) -> None:
    (f / "meshes").symlink_to(out, target_is_directory=True)
    _add(f, '<mesh name="s" file="secret.obj"/>', '<compiler meshdir="meshes"/>')


def _mesh_lexical_dotdot(f: Path, out: Path) -> None:
    # the file system would resolve link/.. inside a/b (inside); MuJoCo drops "link/.."
    # lexically first and reads ../outside
    (f / "a" / "b" / "c").mkdir(parents=True)
    (f / "link").symlink_to(f / "a" / "b" / "c", target_is_directory=True)
    _add(f, '<mesh name="s" file="link/../../outside/secret.obj"/>')


def _mesh_tab(f: Path, out: Path) -> None:
    # expat reads the tab as a space (a harmless file), MuJoCo's tinyxml2 keeps it (a link)
    (f / "ev il.obj").write_text(OBJ)
    (f / "ev\til.obj").symlink_to(out / "secret.obj")
    _add(f, '<mesh name="s" file="ev\til.obj"/>')


def _mesh_drive(f: Path, out: Path) -> None:
    _add(f, '<mesh name="s" file="c:/secret.obj"/>')


def _flexcomp(f: Path, out: Path) -> None:
    (f / "m").mkdir()
    (f / "t" / "u").mkdir(parents=True)
    _add(f, compiler='<compiler meshdir="m" texturedir="t/u"/>',
         body='<flexcomp name="fx" type="mesh" file="../../outside/secret.obj" dim="2"/>')


def _model_asset(f: Path, out: Path) -> None:
    (f / "sub.xml").write_text(f'<mujoco><asset><mesh name="q" file="{out / "secret.obj"}"/>'
                               "</asset></mujoco>")
    _add(f, '<model name="sub" file="sub.xml"/>')


def _include(f: Path, out: Path) -> None:
    (out / "inc.xml").write_text("<mujoco/>")
    _add(f, body=f'<include file="{out / "inc.xml"}"/>')


def _plugin(f: Path, out: Path) -> None:
    xml = (f / "model.xml").read_text().replace(
        "<asset>", '<extension><plugin plugin="mujoco.sdf.torus"/></extension>\n<asset>', 1)
    (f / "model.xml").write_text(xml)


def _doctype(f: Path, out: Path) -> None:
    # tinyxml2 ends the DOCTYPE at the first '>' (inside the entity) and reads the hidden
    # <mujoco> as the model; expat reads it as the entity's text
    hidden = (f"<mujoco><asset><mesh name='s' file='{out / 'secret.obj'}'/></asset>"
              "<worldbody><geom type='mesh' mesh='s'/></worldbody></mujoco>")
    real = (f / "model.xml").read_text()
    (f / "model.xml").write_text(f'<!DOCTYPE mujoco [<!ENTITY x "> {hidden} <!-- ">]> '
                                 f"<!-- --> {real}")


def _urdf(f: Path, out: Path) -> None:
    (f / "model.xml").write_text(
        f'<robot name="r"><mujoco><compiler strippath="false"/></mujoco><link name="a"><visual>'
        f'<geometry><mesh filename="{out / "secret.obj"}"/></geometry></visual></link></robot>')


def _model_symlink(f: Path, out: Path) -> None:
    shutil.copy(f / "model.xml", out / "model.xml")
    (f / "model.xml").unlink()
    (f / "model.xml").symlink_to(out / "model.xml")


def _mesh_fifo(f: Path, out: Path) -> None:
    os.mkfifo(f / "m.obj")  # inside, but MuJoCo would block on it
    _add(f, '<mesh name="s" file="m.obj"/>')


ROUTES = {
    "hfield-meshdir": (_hfield_meshdir, ("<hfield file>", "outside the run folder")),
    "hfield-assetdir": (_hfield_assetdir, ("<hfield file>", "outside the run folder")),
    "hfield-two-compilers": (_hfield_two_compilers, ("<hfield file>", "outside the run folder")),
    "texture-texturedir": (_texture, ("<texture file>", "outside the run folder")),
    "texture-fileup": (_texture_cube, ("<texture fileup>", "outside the run folder")),
    "skin-meshdir": (_skin, ("<skin file>", "outside the run folder")),
    "mesh-dotdot": (_mesh_dotdot, ("<mesh file>", "outside the run folder")),
    "mesh-absolute": (_mesh_absolute, ("<mesh file>", "outside the run folder")),
    "mesh-backslash": (_mesh_backslash, ("<mesh file>", "outside the run folder")),
    "mesh-symlink": (_mesh_symlink, ("<mesh file>", "outside the run folder")),
    "meshdir-symlink": (_mesh_symlink_dir, ("<compiler meshdir>", "outside the run folder")),
    "mesh-lexical-dotdot": (_mesh_lexical_dotdot, ("<mesh file>", "outside the run folder")),
    "mesh-tab": (_mesh_tab, ("<mesh file>", "white space")),
    "mesh-drive": (_mesh_drive, ("<mesh file>", "drive or resource name")),
    "flexcomp": (_flexcomp, ("<flexcomp file>", "outside the run folder")),
    "model-asset": (_model_asset, ("model.xml", "<model file")),
    "include": (_include, ("model.xml", "includes")),
    "plugin": (_plugin, ("model.xml", "plugin")),
    "doctype": (_doctype, ("model.xml", "DOCTYPE")),
    "urdf": (_urdf, ("model.xml", "<robot>", "<mujoco>")),
    "model-symlink": (_model_symlink, ("model.xml", "symbolic link", "outside the run folder")),
    "mesh-fifo": (_mesh_fifo, ("<mesh file>", "a FIFO")),
}


@pytest.mark.parametrize("route", list(ROUTES))
def test_model_xml_never_makes_mujoco_read_outside_the_folder(route, base, tmp_path, capsys,
                                                               no_gl):
    """Each route by which MuJoCo would read a file elsewhere: refused in one line naming the
    folder, model.xml's element and attribute; the secret file is never read and MuJoCo never
    gets the model."""
    folder = _copy(base, tmp_path)
    outside = folder.parent / "outside"
    secrets = _secret(outside)
    make, words = ROUTES[route]
    make(folder, outside)
    for path in secrets.values():
        os.utime(path, (0, path.stat().st_mtime))
    _refused(folder, capsys, *words)
    assert no_gl == []  # refused before anything was compiled or rendered
    if _atime_is_kept(tmp_path):
        assert [p.name for p in secrets.values() if p.stat().st_atime != 0] == []


def _legit_meshdir(f: Path) -> None:
    (f / "meshes").mkdir()
    (f / "meshes" / "tet.obj").write_text(OBJ)
    (f / "meshes" / "h.bin").write_bytes(HFIELD)
    _add(f, '<mesh name="tet" file="tet.obj"/><hfield name="h" size="1 1 1 1" file="h.bin"/>',
         '<compiler meshdir="meshes" texturedir="nowhere/else"/>',
         '<geom type="mesh" mesh="tet" pos="3 3 0"/>')


def _legit_assetdir(f: Path) -> None:
    (f / "assets" / "sub").mkdir(parents=True)
    (f / "assets" / "sub" / "tet.obj").write_text(OBJ)
    (f / "assets" / "h.bin").write_bytes(HFIELD)
    _add(f, '<mesh name="tet" file="sub\\tet.obj"/><hfield name="h" size="1 1 1 1" '
            'file="./sub/../h.bin"/>', '<compiler assetdir="assets"/>')


def _legit_strippath(f: Path) -> None:
    # MuJoCo keeps only the file's name: ../.. never leaves the folder
    (f / "m").mkdir()
    (f / "m" / "tet.obj").write_text(OBJ)
    _add(f, '<mesh name="tet" file="../../elsewhere/tet.obj"/>',
         '<compiler meshdir="m" strippath="true"/>')


def _legit_symlink_inside(f: Path) -> None:
    (f / "real").mkdir()
    (f / "real" / "tet.obj").write_text(OBJ)
    (f / "link.obj").symlink_to(f / "real" / "tet.obj")
    _add(f, '<mesh name="tet" file="link.obj"/>')


@pytest.mark.parametrize("make", [_legit_meshdir, _legit_assetdir, _legit_strippath,
                                  _legit_symlink_inside])
def test_files_inside_the_folder_are_read(make, base, tmp_path, capsys, no_gl):
    """A mesh and height field inside the folder, named through meshdir, assetdir (with ``\\``
    and ``..`` that stay inside), strippath or a symbolic link that stays inside: rendered."""
    folder = _copy(base, tmp_path)
    make(folder)
    rc, err = _render(folder, capsys)
    assert rc == 0 and err == "", err
    model = no_gl[0].load_model()
    assert model.nmesh == 1


def _mj_opens(xml: str) -> str | None:
    """The path MuJoCo fails to open compiling ``xml`` (None when it compiled): the name its
    error gives, as its file system layer reduces it before opening (a flexcomp's name comes
    unreduced: ``a\\zz.obj`` opens ``a/zz.obj``)."""
    import mujoco

    try:
        mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        found = re.search(r"Error opening file '([^']*)'", str(exc))
        assert found, str(exc)
        return runfolder._mj_reduce(found.group(1))
    return None


PART = st.sampled_from(["a", "b", ".", "..", "", "1:"])
PATH = st.lists(st.tuples(PART, st.sampled_from(["/", "\\"])), max_size=4).map(
    lambda parts: "".join(p + s for p, s in parts))
ASSETS = {  # element, what MuJoCo needs besides the file, the file's extension
    "mesh": ('<mesh name="x" file="{}zz.obj"/>', "asset"),
    "hfield": ('<hfield name="x" size="1 1 1 1" file="{}zz.bin"/>', "asset"),
    "skin": ('<skin name="x" file="{}zz.skn"/>', "asset"),
    "texture": ('<texture name="x" type="2d" file="{}zz.png"/>', "asset"),
    "cube": ('<texture name="x" type="cube" fileleft="{}zz.png"/>', "asset"),
    "flexcomp": ('<flexcomp name="x" type="mesh" dim="2" file="{}zz.obj"/>', "worldbody"),
}
COMPILER = st.fixed_dictionaries({}, optional={
    "assetdir": PATH, "meshdir": PATH, "texturedir": PATH,
    "strippath": st.sampled_from(["true", "false"])})


def _mjcf(sections: list[dict[str, str]], kind: str, name: str) -> str:
    element, section = ASSETS[kind]
    compilers = "".join("<compiler " + " ".join(f'{k}="{v}"' for k, v in c.items()) + "/>"
                        for c in sections)
    return f"<mujoco>{compilers}<{section}>{element.format(name)}</{section}></mujoco>"


def _names_as_mujoco(sections: list[dict[str, str]], kind: str, name: str,
                     monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.chdir(tmp_path)  # the names are relative: nothing of them exists here
    xml = _mjcf(sections, kind, name)
    names = [n for _, _, n, is_dir in model_file_names(xml.encode(), "test") if not is_dir]
    assert names == [_mj_opens(xml)], xml


@FUZZ
@given(sections=st.lists(COMPILER, max_size=3), kind=st.sampled_from(sorted(ASSETS)),
       name=PATH)
def test_file_names_are_resolved_as_mujoco_resolves_them(sections, kind, name, monkeypatch,
                                                         tmp_path):
    """Several <compiler> sections (assetdir, meshdir, texturedir, strippath, in any order),
    every element that reads a file, names with ``/``, ``\\``, ``.``, ``..``, empty parts and
    ``1:/`` prefixes (absolute to MuJoCo): the name cellsim checks is the one MuJoCo opens."""
    _names_as_mujoco(sections, kind, name, monkeypatch, tmp_path)


@pytest.mark.slow
@FUZZ_SLOW
@given(sections=st.lists(COMPILER, max_size=4), kind=st.sampled_from(sorted(ASSETS)),
       name=PATH)
def test_file_names_are_resolved_as_mujoco_resolves_them_many(sections, kind, name,
                                                              monkeypatch, tmp_path):
    _names_as_mujoco(sections, kind, name, monkeypatch, tmp_path)


@pytest.mark.parametrize("sections, kind, expected", [
    ('<compiler meshdir="M" texturedir="T"/>', "hfield", "M/zz.bin"),
    ('<compiler assetdir="A"/>', "hfield", "A/zz.bin"),
    ('<compiler meshdir="M" assetdir="A"/>', "hfield", "M/zz.bin"),
    ('<compiler meshdir="M"/><compiler assetdir="A"/>', "mesh", "A/zz.obj"),
    ('<compiler assetdir="A"/><compiler meshdir="M"/>', "texture", "A/zz.png"),
    ('<compiler meshdir="M" texturedir="T"/>', "skin", "M/zz.skn"),
    ('<compiler meshdir="M" texturedir="T"/>', "cube", "T/zz.png"),
    ('<compiler meshdir="M"/><compiler meshdir=""/>', "mesh", "zz.obj"),
    ('<compiler meshdir="/abs"/>', "mesh", "/abs/zz.obj"),
])
def test_compiler_sections_as_mujoco_reads_them(sections, kind, expected, monkeypatch,
                                                tmp_path):
    """The documented cases, each checked against MuJoCo itself: meshdir is a height field's
    and a skin's dir, assetdir sets both dirs unless the same section sets one, a later
    section overrides an earlier one, an empty dir resets it, an absolute dir is kept."""
    monkeypatch.chdir(tmp_path)
    element, section = ASSETS[kind]
    xml = f"<mujoco>{sections}<{section}>{element.format('')}</{section}></mujoco>"
    names = [n for _, _, n, is_dir in model_file_names(xml.encode(), "t") if not is_dir]
    assert names == [expected] == [_mj_opens(xml)]


# -------------------------------------------------------------------- trajectory.npz
def _arrays(folder: Path) -> dict[str, np.ndarray]:
    with np.load(folder / "trajectory.npz") as npz:
        return {k: npz[k] for k in npz.files}


def _npy(array: np.ndarray, allow_pickle: bool = False) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array, allow_pickle=allow_pickle)
    return buf.getvalue()


def _with_member(folder: Path, name: str, data: bytes, drop: str | None = None) -> None:
    arrays = _arrays(folder)
    arrays.pop(drop or "", None)
    np.savez_compressed(folder / "trajectory.npz", **arrays)
    with zipfile.ZipFile(folder / "trajectory.npz", "a") as zf:
        zf.writestr(name, data)


def _huge_header(shape: tuple[int, ...]) -> bytes:
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False,
                                                  "shape": shape})
    return header.getvalue() + b"\0" * 64


def _set(name: str, value) -> callable:
    def edit(folder: Path) -> None:
        arrays = _arrays(folder)
        arrays[name] = value(arrays) if callable(value) else value
        np.savez_compressed(folder / "trajectory.npz", **arrays)
    return edit


def _replace(make) -> callable:
    def edit(folder: Path) -> None:
        (folder / "trajectory.npz").unlink()
        make(folder / "trajectory.npz")
    return edit


def _truncate(keep) -> callable:
    def edit(folder: Path) -> None:
        path = folder / "trajectory.npz"
        data = path.read_bytes()
        path.write_bytes(data[:keep(len(data))])
    return edit


def _lzma(folder: Path) -> None:
    arrays = _arrays(folder)
    with zipfile.ZipFile(folder / "trajectory.npz", "w", compression=zipfile.ZIP_LZMA) as zf:
        for key, value in arrays.items():
            zf.writestr(key + ".npy", _npy(value))


def _wrapping_times(a):
    t = np.arange(len(a["t"]), dtype=np.uint64)
    t[-1] = 0  # np.diff wraps round to a huge positive step
    return t


NPZ_CASES = {
    "pickled-object-array": lambda f: _with_member(
        f, "obj.npy", _npy(np.array([{"a": 1}], dtype=object), allow_pickle=True)),
    "member-not-npy": lambda f: _with_member(f, "evil", b"\x80\x04K\x01."),
    "npy-holding-pickle": lambda f: _with_member(f, "evil.npy", b"\x80\x04K\x01."),
    "string-times": _set("t", lambda a: a["t"].astype("U12")),
    "bytes-times": _set("t", lambda a: a["t"].astype("S12")),
    "0-d-times": _set("t", np.array(1.0)),
    "0-d-qpos": _set("qpos", np.array(1.0)),
    "0-d-knot_t": _set("knot_t", np.array(1.0)),
    "uint-times-wrapping": _set("t", _wrapping_times),
    "2-d-arc_on": _set("arc_on", lambda a: np.zeros((len(a["t"]), 3), bool)),
    "2-d-phase": _set("phase", lambda a: np.zeros((len(a["t"]), 2))),
    "complex-tau": _set("tau", lambda a: a["tau"].astype(complex)),
    "huge-shape": lambda f: _with_member(f, "qpos.npy", _huge_header((10**6, 10**6)), "qpos"),
    "huge-1-d-shape": lambda f: _with_member(f, "qpos.npy", _huge_header((2**62,)), "qpos"),
    "truncated-half": _truncate(lambda n: n // 2),
    "truncated-10": _truncate(lambda n: n - 10),
    "empty": _truncate(lambda n: 0),
    "directory": _replace(lambda p: p.mkdir()),
    "fifo": _replace(os.mkfifo),
    "plain-npy": _replace(lambda p: p.write_bytes(_npy(np.arange(5.0)))),
    "lzma-members": _lzma,
}


@pytest.mark.parametrize("case", list(NPZ_CASES))
def test_damaged_trajectory_is_one_line(case, base, tmp_path, capsys):
    """A member that is no array, or not numbers, of the wrong rank, claiming a huge shape;
    a truncated, empty, or non-zip file, a folder or a FIFO in its place: one line naming the
    folder and trajectory.npz, exit 2."""
    import tracemalloc

    folder = _copy(base, tmp_path)
    NPZ_CASES[case](folder)
    tracemalloc.start()
    try:
        _refused(folder, capsys, "trajectory.npz")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 * 1024**2  # a huge shape in a header allocates nothing


def _flip_bits(base: Path, tmp_path: Path, every: int, every_in_directory: int) -> None:
    """Flip one bit in every ``every``-th byte of trajectory.npz (``every_in_directory``-th in
    the zip's central directory and end record): either the file still reads as the same
    arrays (a flip in a time stamp or an unused field) or it is refused in one line naming
    trajectory.npz, never read as other arrays."""
    data = (base / "trajectory.npz").read_bytes()
    directory = data.rfind(b"PK\x01\x02")
    same = _arrays(base)
    positions = sorted({*range(0, len(data), every),
                        *range(directory, len(data), every_in_directory)})
    path = tmp_path / "trajectory.npz"
    refused = 0
    for pos in positions:
        spoilt = bytearray(data)
        spoilt[pos] ^= 1 << (pos % 8)
        path.write_bytes(bytes(spoilt))
        try:
            arrays = runfolder._read_trajectory(path, "run")
        except RunFolderError as exc:
            assert "trajectory.npz" in str(exc) and "\n" not in str(exc), (pos, exc)
            refused += 1
        else:
            assert sorted(arrays) == sorted(same), pos
            assert all(np.array_equal(arrays[k], same[k]) for k in same), pos
    assert refused > 0.75 * len(positions), (refused, len(positions))


def test_a_bit_flip_anywhere_in_trajectory_npz(base, tmp_path, capsys):
    """Bit flips through the members' headers and data, the zip's local headers, central
    directory and end record: the same arrays or one line (:func:`_flip_bits`)."""
    _flip_bits(base, tmp_path, 97, 7)
    folder = _copy(base, tmp_path)  # and through the CLI
    spoilt = bytearray((folder / "trajectory.npz").read_bytes())
    spoilt[len(spoilt) // 2] ^= 0x10
    (folder / "trajectory.npz").write_bytes(bytes(spoilt))
    _refused(folder, capsys, "trajectory.npz")


@pytest.mark.slow
def test_a_bit_flip_in_every_byte_of_trajectory_npz(base, tmp_path):
    _flip_bits(base, tmp_path, 1, 1)


def test_trajectory_size_is_bounded_before_it_is_unpacked(base, tmp_path, capsys,
                                                          monkeypatch):
    """The bound on what trajectory.npz unpacks to holds before anything is unpacked (here a
    bound of 100 kB against a 2 MB array of zeros that packs into a few kB)."""
    folder = _copy(base, tmp_path)
    _set("zeros", lambda a: np.zeros((len(a["t"]), 12_000)))(folder)
    assert (folder / "trajectory.npz").stat().st_size < 100_000
    assert load_run(folder).get("zeros").shape == (21, 12_000)
    monkeypatch.setattr(runfolder.reading, "MAX_TRAJECTORY_BYTES", 100_000)  # the reader's bound
    _refused(folder, capsys, "trajectory.npz", "unpacks to", "100,000")


def _damage_bytes(data: bytes, flips: list[tuple[int, int]], cut: int | None) -> bytes:
    spoilt = bytearray(data)
    for pos, bit in flips:
        spoilt[pos % len(spoilt)] ^= 1 << bit
    return bytes(spoilt[:cut] if cut is not None else spoilt)


DAMAGE = {"flips": st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 7)), min_size=1,
                            max_size=3),
          "cut": st.none() | st.integers(0, 10**6)}


def _fuzz_trajectory(base: Path, tmp_path: Path, capsys, flips, cut) -> None:
    folder = _copy(base, tmp_path)
    path = folder / "trajectory.npz"
    path.write_bytes(_damage_bytes(path.read_bytes(), flips, cut))
    rc, err = _render(folder, capsys)
    if rc == 2:
        assert err.count("\n") == 1 and str(folder) in err and "trajectory.npz" in err, err
    shutil.rmtree(folder.parent)


@FUZZ
@given(**DAMAGE)
def test_random_damage_to_trajectory_npz(base, tmp_path, capsys, flips, cut):
    _fuzz_trajectory(base, tmp_path, capsys, flips, cut)


@pytest.mark.slow
@FUZZ_SLOW
@given(**DAMAGE)
def test_random_damage_to_trajectory_npz_many(base, tmp_path, capsys, flips, cut):
    _fuzz_trajectory(base, tmp_path, capsys, flips, cut)


# ---------------------------------------------------------------------- summary.json
def _summary(**changes) -> callable:
    def edit(folder: Path) -> None:
        summary = json.loads((folder / "summary.json").read_text())
        summary.update(changes)
        (folder / "summary.json").write_text(json.dumps(summary))
    return edit


def _raw(data: bytes) -> callable:
    def edit(folder: Path) -> None:
        (folder / "summary.json").write_bytes(data)
    return edit


def _summary_link(folder: Path) -> None:
    outside = folder.parent / "outside.json"
    shutil.copy(folder / "summary.json", outside)
    (folder / "summary.json").unlink()
    (folder / "summary.json").symlink_to(outside)


SUMMARY_CASES = {
    "phases-object": (_summary(phases={"name": "a"}), "'phases'"),
    "phases-string": (_summary(phases=["weld"]), "'phases'[0]"),
    "phases-number": (_summary(phases=[3]), "'phases'[0]"),
    "phases-null": (_summary(phases=[None]), "'phases'[0]"),
    "phase-t0-after-t1": (_summary(phases=[{"name": "a", "t0": 2.0, "t1": 1.0}]),
                          "'phases'[0]"),
    "phase-nan": (_summary(phases=[{"name": "a", "t0": float("nan"), "t1": 1.0}]),
                  "'phases'[0].t0"),
    "phase-inf": (_summary(phases=[{"name": "a", "t0": 0, "t1": float("inf")}]),
                  "'phases'[0].t1"),
    "phase-time-string": (_summary(phases=[{"name": "a", "t0": "0", "t1": 1}]),
                          "'phases'[0].t0"),
    "phase-time-bool": (_summary(phases=[{"name": "a", "t0": False, "t1": 1}]),
                        "'phases'[0].t0"),
    "phase-no-t1": (_summary(phases=[{"name": "a", "t0": 0}]), "'phases'[0]"),
    "phase-name-number": (_summary(phases=[{"name": 5, "t0": 0, "t1": 1}]),
                          "'phases'[0].name"),
    "phase-name-null": (_summary(phases=[{"name": None, "t0": 0, "t1": 1}]),
                        "'phases'[0].name"),
    "phase-kind-list": (_summary(phases=[{"name": "a", "kind": [], "t0": 0, "t1": 1}]),
                        "'phases'[0].kind"),
    "joints-string": (_summary(joints="j1"), "'joints'"),
    "joints-numbers": (_summary(joints=[1, 2, 3, 4]), "'joints'"),
    "joints-too-few": (_summary(joints=["j1", "j2"]), "'joints' names 2 joints"),
    "joints-too-many": (_summary(joints=["a", "b", "c", "d", "e"]), "'joints' names 5 joints"),
    "collisions-string": (_summary(collisions="x"), "'collisions'"),
    "collisions-of-strings": (_summary(collisions=["x"]), "'collisions'[0]"),
    "collision-no-times": (_summary(collisions=[{"geoms": ["floor"]}]), "'collisions'[0]"),
    "collision-geoms-number": (_summary(collisions=[{"geoms": 3, "t0": 0, "t1": 1}]),
                               "'collisions'[0].geoms"),
    "deep-nesting": (_raw(b"[" * 100_000 + b"]" * 100_000), "nests too deeply"),
    "not-utf8": (_raw(b'{"joints": ["j\xff"]}'), "not UTF-8"),
    "huge-integer": (_raw(b'{"x": ' + b"9" * 5000 + b"}"), "not valid JSON"),
    "a-list": (_raw(b"[1, 2]"), "JSON object"),
    "not-json": (_raw(b"{'a': 1}"), "not valid JSON"),
    "fifo": (lambda f: ((f / "summary.json").unlink(), os.mkfifo(f / "summary.json")),
             "a FIFO"),
    "directory": (lambda f: ((f / "summary.json").unlink(), (f / "summary.json").mkdir()),
                  "a folder"),
    "symlink-outside": (_summary_link, "outside the run folder"),
}


@pytest.mark.parametrize("case", list(SUMMARY_CASES))
def test_damaged_summary_is_one_line(case, base, tmp_path, capsys):
    """Each malformed field of summary.json, deep nesting, bytes that are not UTF-8, a FIFO or
    a folder in its place, a link elsewhere: one line naming the folder, summary.json and the
    field, exit 2."""
    folder = _copy(base, tmp_path)
    edit, words = SUMMARY_CASES[case]
    edit(folder)
    _refused(folder, capsys, "summary.json", words)


def test_a_fifo_marker_does_not_block(base, tmp_path, capsys):
    """A FIFO in the place of the marker file (read before anything else) counts as none."""
    folder = _copy(base, tmp_path)
    os.mkfifo(folder / runfolder.MARKER)
    assert _render(folder, capsys)[0] == 0


def test_other_files_linked_elsewhere_are_refused(base, tmp_path, capsys):
    folder = _copy(base, tmp_path)
    outside = folder.parent / "elsewhere.npz"
    (folder / "trajectory.npz").rename(outside)
    (folder / "trajectory.npz").symlink_to(outside)
    _refused(folder, capsys, "trajectory.npz", "symbolic link", "outside the run folder")


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(
        st.sampled_from(["name", "kind", "t0", "t1", "geoms", "all_geoms", "x"]), inner,
        max_size=4),
    max_leaves=12)
FIELD = st.sampled_from(["phases", "joints", "collisions", "duration_s", "scenario"])
PHASE = st.fixed_dictionaries({}, optional={"name": JSON, "kind": JSON, "t0": JSON, "t1": JSON})


def _fuzz_summary(base: Path, tmp_path: Path, capsys, field: str, value) -> None:
    folder = _copy(base, tmp_path)
    _summary(**{field: value})(folder)
    rc, err = _render(folder, capsys)
    if rc == 2:
        assert err.count("\n") == 1 and str(folder) in err, err
        assert "summary.json" in err and repr(field) in err, err
    shutil.rmtree(folder.parent)


@FUZZ
@given(field=FIELD, value=JSON | st.lists(PHASE, max_size=3))
def test_random_summary_values(base, tmp_path, capsys, field, value):
    _fuzz_summary(base, tmp_path, capsys, field, value)


@pytest.mark.slow
@FUZZ_SLOW
@given(field=FIELD, value=JSON | st.lists(PHASE, max_size=3))
def test_random_summary_values_many(base, tmp_path, capsys, field, value):
    _fuzz_summary(base, tmp_path, capsys, field, value)
