"""Mechanism files for tests (docs/mechanism-format.md): a TOML writer (:func:`toml_text`,
:func:`write`), hypothesis strategies of valid files (:func:`mechanism_docs`), and the oracle
that judges a read :class:`~sim.robots.mechanisms.spec.MechanismSpec` against the file's own
numbers (:func:`mismatches`), written from first principles: mm -> m is ``/ 1000``, deg -> rad
``* pi / 180``, an axis normalised by its Euclidean length, ``Rz Ry Rx`` from the explicit
matrices. Nothing here is a test.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

from sim.robots.mechanisms import MechanismSpec
from support.toml_values import toml_value

# ----------------------------------------------------------------------------- TOML writing
_value = toml_value  # the shared writer (toml_values.py)


def toml_text(doc: dict[str, Any], prefix: str = "") -> str:
    """``doc`` as TOML in block syntax (``[table]``, ``[[array.of.tables]]``)."""
    lines: list[str] = []

    def tables(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)

    for k, v in doc.items():
        if not isinstance(v, dict) and not tables(v):
            lines.append(f"{k} = {_value(v)}")
    for k, v in doc.items():
        if isinstance(v, dict):
            lines += ["", f"[{prefix}{k}]", toml_text(v, f"{prefix}{k}.")]
    for k, v in doc.items():
        if tables(v):
            for item in v:
                lines += ["", f"[[{prefix}{k}]]", toml_text(item, f"{prefix}{k}.")]
    return "\n".join(lines)


def write(tmp: Path, doc: dict[str, Any], name: str = "mech.toml") -> Path:
    path = tmp / name
    path.write_text(toml_text(doc) + "\n", encoding="utf-8")
    return path


# --------------------------------------------------------------------------------- oracles
def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])


def rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def zyx(deg: list[float]) -> np.ndarray:
    a, b, c = (math.pi / 180.0 * v for v in deg)
    return rz(a) @ ry(b) @ rx(c)


def rodrigues(u: np.ndarray, q: float) -> np.ndarray:
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * k @ k


DEG = math.pi / 180.0


def mismatches(spec: MechanismSpec, doc: dict[str, Any], stem: str) -> list[str]:
    """Where ``spec`` is not what ``doc`` (the file's own numbers) says, converted to SI here."""
    bad: list[str] = []

    def close(what: str, got: Any, want: Any, atol: float = 0.0) -> None:
        """Equal to 1e-12 relative; ``atol`` only for entries of unit size (a rotation, an axis
        direction), whose zeros the two ways of computing them round differently."""
        if not np.allclose(np.asarray(got, float), np.asarray(want, float), rtol=1e-12,
                           atol=atol):
            bad.append(f"{what}: {got!r} != {want!r}")

    def same(what: str, got: Any, want: Any) -> None:
        if got != want:
            bad.append(f"{what}: {got!r} != {want!r}")

    def shapes(what: str, got: Any, want: list[dict[str, Any]], prefix: str) -> None:
        same(f"{what} count", len(got), len(want))
        for i, (s, w) in enumerate(zip(got, want, strict=False)):
            same(f"{what}[{i}].name", s.name, w.get("name", f"{prefix}{i}"))
            same(f"{what}[{i}].kind", s.kind, w["kind"])
            if w["kind"] == "box":
                close(f"{what}[{i}].size", s.size, [v / 2000.0 for v in w["size_mm"]])
            else:
                close(f"{what}[{i}].size", s.size,
                      [w["radius_mm"] / 1000.0, w["length_mm"] / 2000.0, 0.0])
            close(f"{what}[{i}].pos", s.pos, [v / 1000.0 for v in w.get("pos_mm", [0, 0, 0])])
            close(f"{what}[{i}].rot", s.rot, zyx(w.get("euler_zyx_deg", [0, 0, 0])), 1e-14)
            close(f"{what}[{i}].rgba", s.rgba, w.get("rgba", [0.95, 0.6, 0.1, 1.0]))

    name = doc.get("name", stem)
    same("name", spec.name, name)
    same("title", spec.title, doc.get("title") or name)
    same("kind", spec.kind, doc["kind"])
    same("description", spec.description, doc.get("description", ""))
    close("payload", spec.payload_kg, doc.get("payload_kg", 0.0))
    same("axes", len(spec.axes), len(doc["axes"]))
    for i, (a, w) in enumerate(zip(spec.axes, doc["axes"], strict=False)):
        k = f"axes[{i}]"
        rev = w["kind"] == "revolute"
        f = DEG if rev else 1e-3
        same(f"{k}.name", a.name, w["name"])
        same(f"{k}.kind", a.kind, w["kind"])
        close(f"{k}.pos", a.pos, [v / 1000.0 for v in w.get("pos_mm", [0, 0, 0])])
        v = np.asarray(w["axis"], float)
        close(f"{k}.axis", a.axis, v / math.sqrt(float(v @ v)), 1e-14)
        r = w["range_deg"] if rev else w["range_mm"]
        close(f"{k}.range", a.range, [r[0] * f, r[1] * f])
        close(f"{k}.max_speed", a.max_speed, w["max_speed_deg_s" if rev else "max_speed_mm_s"] * f)
        close(f"{k}.max_accel", a.max_accel,
              w["max_accel_deg_s2" if rev else "max_accel_mm_s2"] * f)
        close(f"{k}.friction", a.friction, w.get("friction_nm" if rev else "friction_n", 0.0))
        close(f"{k}.damping", a.damping, w.get("damping", 0.0))
        d = w["drive"]
        for field, key in (("gear_ratio", "gear_ratio"), ("efficiency", "efficiency"),
                           ("rotor_inertia", "rotor_inertia_kg_m2"),
                           ("rated_torque", "rated_torque_nm"), ("peak_torque", "peak_torque_nm"),
                           ("max_speed_rpm", "max_speed_rpm")):
            close(f"{k}.drive.{field}", getattr(a.drive, field), d[key])
        lk = w["link"]
        close(f"{k}.link.mass", a.link.mass, lk["mass_kg"])
        close(f"{k}.link.com", a.link.com, [v / 1000.0 for v in lk["com_mm"]])
        close(f"{k}.link.inertia", a.link.inertia, lk["inertia_kg_m2"])
        shapes(f"{k}.link.shapes", a.link.shapes, lk.get("shapes", []), w["name"])
    shapes("base_shapes", spec.base_shapes, doc.get("base_shapes", []), "base")
    m = doc.get("mount", {})
    want = np.eye(4)
    want[:3, :3] = zyx(m.get("euler_zyx_deg", [0, 0, 0]))
    want[:3, 3] = [v / 1000.0 for v in m.get("pos_mm", [0, 0, 0])]
    close("mount rotation", spec.mount[:3, :3], want[:3, :3], 1e-14)
    close("mount position", spec.mount[:3, 3], want[:3, 3])
    close("mount last row", spec.mount[3], [0, 0, 0, 1])
    return bad


# ------------------------------------------------------------------------------ generation
def floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


@st.composite
def shape_docs(draw: st.DrawFn, name: str | None) -> dict[str, Any]:
    s: dict[str, Any] = {}
    if name is not None:
        s["name"] = name
    if draw(st.booleans()):
        s["kind"] = "box"
        s["size_mm"] = draw(st.lists(floats(0.01, 1e4), min_size=3, max_size=3))
    else:
        s["kind"] = "cylinder"
        s["radius_mm"] = draw(floats(0.01, 1e4))
        s["length_mm"] = draw(floats(0.01, 1e4))
    if draw(st.booleans()):
        s["pos_mm"] = draw(st.lists(floats(-1e5, 1e5), min_size=3, max_size=3))
    if draw(st.booleans()):
        s["euler_zyx_deg"] = draw(st.lists(floats(-720, 720), min_size=3, max_size=3))
    if draw(st.booleans()):
        s["rgba"] = draw(st.lists(floats(0, 1), min_size=4, max_size=4))
    return s


@st.composite
def mechanism_docs(draw: st.DrawFn) -> dict[str, Any]:
    """A valid mechanism file's table, numbers anywhere in their documented ranges."""
    kind = draw(st.sampled_from(["turntable", "positioner", "track"]))
    n = draw(st.integers(1, 3)) if kind == "positioner" else 1
    axis_kind = "prismatic" if kind == "track" else "revolute"
    doc: dict[str, Any] = {"kind": kind}
    if draw(st.booleans()):
        doc["name"] = draw(st.from_regex(r"[a-z][a-z0-9_]{0,10}", fullmatch=True))
    if draw(st.booleans()):
        doc["title"] = draw(st.text("abcXYZ 0123-()", max_size=20))
    if draw(st.booleans()):
        doc["payload_kg"] = draw(floats(0, 1e5))
    axes = []
    shape_id = iter(range(1000))
    for i in range(n):
        rev = axis_kind == "revolute"
        lim = 1080.0 if rev else 1e5
        lo = draw(floats(-lim, lim * 0.999))
        hi = draw(floats(lo + 1e-3, lim))
        vec = draw(st.lists(floats(-1e6, 1e6), min_size=3, max_size=3).filter(
            lambda v: max(abs(x) for x in v) >= 1e-3))
        a, b = draw(floats(1e-3, 100)), draw(floats(1e-3, 100))
        c = draw(floats(abs(a - b), a + b).filter(lambda x: x >= 1e-12))
        inertia = draw(st.permutations([a, b, c]))
        rated = draw(floats(1e-3, 1e3))
        u = "deg" if rev else "mm"
        ax: dict[str, Any] = {
            "name": f"ax{i}", "kind": axis_kind, "axis": vec,
            f"range_{u}": [lo, hi],
            f"max_speed_{u}_s": draw(floats(1e-3, 1e5)),
            f"max_accel_{u}_s2": draw(floats(1e-3, 1e7)),
            "drive": {"gear_ratio": draw(floats(0.01, 1e4)), "efficiency": draw(floats(0.01, 1)),
                      "rotor_inertia_kg_m2": draw(floats(0, 100)), "rated_torque_nm": rated,
                      "peak_torque_nm": draw(floats(rated, 1e6)),
                      "max_speed_rpm": draw(floats(1e-3, 1e6))},
            "link": {"mass_kg": draw(floats(1e-6, 1e5)),
                     "com_mm": draw(st.lists(floats(-1e5, 1e5), min_size=3, max_size=3)),
                     "inertia_kg_m2": list(inertia)},
        }
        if draw(st.booleans()):
            ax["pos_mm"] = draw(st.lists(floats(-1e5, 1e5), min_size=3, max_size=3))
        if draw(st.booleans()):
            ax["friction_nm" if rev else "friction_n"] = draw(floats(0, 1e6))
        if draw(st.booleans()):
            ax["damping"] = draw(floats(0, 1e7))
        ns = draw(st.integers(0, 2))
        ax["link"]["shapes"] = [
            draw(shape_docs(None if draw(st.booleans()) else f"s{next(shape_id)}"))
            for _ in range(ns)]
        axes.append(ax)
    doc["axes"] = axes
    doc["base_shapes"] = [draw(shape_docs(None if draw(st.booleans()) else f"s{next(shape_id)}"))
                          for _ in range(draw(st.integers(0, 2)))]
    if draw(st.booleans()):
        doc["mount"] = {"pos_mm": draw(st.lists(floats(-1e5, 1e5), min_size=3, max_size=3)),
                        "euler_zyx_deg": draw(st.lists(floats(-720, 720), min_size=3, max_size=3))}
    return doc
