"""FANUC TP positions with extended axes and a second motion group (issue 28).

``E1=``, ``E2=``, .. (deg or mm) after GP1's values and a ``GP2:`` block (a positioner's joints)
are read, kept in SI with their units, and written back; ``DEFAULT_GROUP`` names the groups
every position holds; ``COORD`` is kept as a flag of its motion.

The oracle is the test's own text: programs are generated as integers (thousandths of a mm or
a deg), written into TP text here with their decimal digits spelled out (independent of
``write_ls``), and the parsed values are checked against the integers converted from first
principles (deg * pi / 180, mm / 1000). ``write_ls``'s text is checked the same way: the
numbers it writes, read back out of its text with a regular expression, are the generated
ones to three decimals.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sim.errors import ScenarioError
from sim.scenario.fanuc_ls import LSMotion, parse_ls, write_ls
from sim.scenario.fanuc_pos import LSGroup, LSPosition

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


def dec(k: int) -> str:
    """The thousandths ``k`` as a decimal with three digits after the point (spelled out)."""
    sign = "-" if k < 0 else ""
    return f"{sign}{abs(k) // 1000}.{abs(k) % 1000:03d}"


def si(k: int, unit: str) -> float:
    """``k`` thousandths of ``unit`` in SI: deg -> rad, mm -> m."""
    return (k / 1000) * math.pi / 180 if unit == "deg" else (k / 1000) / 1000


# ------------------------------------------------------------------ generated programs
# A program spec: groups (1,) or (1, 2); positions {n: spec}; motions [(kind, n, options)].
# A position spec: {"uf", "ut", "cart": [6 ints] | None, "joints": [6 ints] | None, "config",
# "ext": [(int, unit)], "gp2": None | {"uf", "ut", "joints": [(int, unit)]}}.

VALUE = st.integers(-2_000_000, 2_000_000)
UNIT = st.sampled_from(["deg", "mm"])


@st.composite
def positions_spec(draw, with_gp2: bool) -> dict:
    cart = draw(st.booleans())
    spec = {"uf": draw(st.integers(0, 9)), "ut": draw(st.integers(0, 9)),
            "cart": draw(st.lists(VALUE, min_size=6, max_size=6)) if cart else None,
            "joints": None if cart else draw(st.lists(VALUE, min_size=6, max_size=6)),
            "config": (draw(st.sampled_from("NF")), draw(st.sampled_from("UD")),
                       draw(st.sampled_from("TB")), *draw(st.lists(st.integers(-2, 2),
                                                                   min_size=3, max_size=3))),
            "ext": draw(st.lists(st.tuples(VALUE, UNIT), max_size=3)), "gp2": None}
    if with_gp2:
        spec["gp2"] = {"uf": draw(st.integers(0, 9)), "ut": draw(st.integers(0, 9)),
                       "joints": draw(st.lists(st.tuples(VALUE, UNIT), min_size=1, max_size=3))}
    return spec


@st.composite
def program_spec(draw) -> dict:
    with_gp2 = draw(st.booleans())
    n = draw(st.integers(1, 4))
    positions = {k: draw(positions_spec(with_gp2)) for k in range(1, n + 1)}
    flags = st.lists(st.sampled_from(["COORD", "PTH", "Wjnt", "INC"]), unique=True, max_size=3)
    motions = [(draw(st.sampled_from("JL")), draw(st.integers(1, n)), draw(flags))
               for _ in range(draw(st.integers(1, 5)))]
    return {"groups": (1, 2) if with_gp2 else (1,), "positions": positions,
            "motions": motions, "style": draw(st.sampled_from(["fixed", "loose", "tight"]))}


def _value(name: str, k: int, unit: str, style: str) -> str:
    """One ``NAME = value unit`` item in one of three spellings a controller or a person
    writes."""
    if style == "fixed":
        eq = "=" if name[0] in "JE" else " = "
        return f"{name}{eq}{dec(k):>10}  {unit}"
    if style == "loose":
        return f"{name} = {dec(k)} {unit}"
    return f"{name}={dec(k)}{unit}"


def hand_text(spec: dict) -> str:
    """The program as TP text, written here without ``write_ls``."""
    style = spec["style"]
    mask = ",".join("1" if g in spec["groups"] else "*" for g in range(1, 6))
    out = ["/PROG  GEN", "/ATTR", "OWNER\t\t= MNEDITOR;", f"DEFAULT_GROUP\t= {mask};", "/MN"]
    for i, (kind, n, flags) in enumerate(spec["motions"], start=1):
        speed = "50%" if kind == "J" else "100mm/sec"
        out.append(f"{i:4d}:{kind} P[{n}] {speed} FINE{''.join(' ' + f for f in flags)}    ;")
    out.append("/POS")
    for n, p in spec["positions"].items():
        out += [f"P[{n}]{{", "   GP1:"]
        if p["cart"] is not None:
            c = p["config"]
            out.append(f"\tUF : {p['uf']}, UT : {p['ut']},\t\tCONFIG : '{c[0]} {c[1]} {c[2]}, "
                       f"{c[3]}, {c[4]}, {c[5]}',")
            items = [_value(a, k, "mm" if a in "XYZ" else "deg", style)
                     for a, k in zip("XYZWPR", p["cart"], strict=True)]
        else:
            out.append(f"\tUF : {p['uf']}, UT : {p['ut']},")
            items = [_value(f"J{j}", k, "deg", style) for j, k in enumerate(p["joints"], 1)]
        items += [_value(f"E{j}", k, u, style) for j, (k, u) in enumerate(p["ext"], 1)]
        out += ["\t" + ",\t".join(items[r:r + 3]) + ("," if r + 3 < len(items) else "")
                for r in range(0, len(items), 3)]
        if p["gp2"] is not None:
            g = p["gp2"]
            out += ["   GP2:", f"\tUF : {g['uf']}, UT : {g['ut']},",
                    "\t" + ",\t".join(_value(f"J{j}", k, u, style)
                                      for j, (k, u) in enumerate(g["joints"], 1))]
        out.append("};")
    out.append("/END")
    return "\n".join(out) + "\n"


def close(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-12 * max(1.0, abs(b))


def mismatches(spec: dict, prog) -> list[str]:
    """Where the parsed program differs from the spec (the oracle): an empty list when none."""
    bad = []
    if prog.groups != spec["groups"]:
        bad.append(f"groups {prog.groups} != {spec['groups']}")
    if sorted(prog.positions) != sorted(spec["positions"]):
        return [*bad, f"positions {sorted(prog.positions)}"]
    for n, p in spec["positions"].items():
        q = prog.positions[n]
        if (q.uf, q.ut) != (p["uf"], p["ut"]):
            bad.append(f"P[{n}] frames")
        if p["cart"] is not None:
            if q.xyzwpr != tuple(k / 1000 for k in p["cart"]) or q.config != p["config"]:
                bad.append(f"P[{n}] Cartesian {q.xyzwpr} {q.config}")
        elif q.joints_deg != tuple(k / 1000 for k in p["joints"]):
            bad.append(f"P[{n}] joints {q.joints_deg}")
        want = [si(k, u) for k, u in p["ext"]]
        if (len(q.ext) != len(want) or not all(map(close, q.ext, want))
                or q.ext_units != tuple(u for _, u in p["ext"])):
            bad.append(f"P[{n}] ext {q.ext} {q.ext_units} != {want}")
        kinds = tuple({"deg": "revolute", "mm": "prismatic"}[u] for _, u in p["ext"])
        if q.ext_kinds != kinds:
            bad.append(f"P[{n}] ext kinds {q.ext_kinds}")
        g = p["gp2"]
        if g is None:
            if q.groups or q.gp2 is not None:
                bad.append(f"P[{n}] has groups {q.groups}")
            continue
        h = q.gp2
        want = [si(k, u) for k, u in g["joints"]]
        if (h is None or (h.uf, h.ut) != (g["uf"], g["ut"]) or h.joints is None
                or len(h.joints) != len(want) or not all(map(close, h.joints, want))
                or h.joint_units != tuple(u for _, u in g["joints"])):
            bad.append(f"P[{n}] GP2 {h}")
    motions = [m for m in prog.instructions if isinstance(m, LSMotion)]
    got = [(m.kind, m.target[1], list(m.options)) for m in motions]
    if got != [(k, n, f) for k, n, f in spec["motions"]]:
        bad.append(f"motions {got}")
    return bad


@SETTINGS
@given(program_spec())
def test_generated_extended_axes_and_gp2_text_is_read_as_written(spec):
    """The text written here from the numbers is read back to them (SI, with units)."""
    prog = parse_ls(hand_text(spec), "gen.ls")
    assert mismatches(spec, prog) == []


def _perturbed(prog):
    """The parsed program with one value moved by a thousandth of its unit (a planted fault)."""
    k = min(prog.positions)
    p = prog.positions[k]
    if p.ext:
        p = replace(p, ext=(p.ext[0] + 1e-6, *p.ext[1:]))
    elif p.gp2 is not None:
        g = replace(p.gp2, joints=(p.gp2.joints[0] + 1e-6, *p.gp2.joints[1:]))
        p = replace(p, groups=(g,))
    elif p.xyzwpr is not None:
        p = replace(p, xyzwpr=(p.xyzwpr[0] + 1e-3, *p.xyzwpr[1:]))
    else:
        p = replace(p, joints_deg=(p.joints_deg[0] + 1e-3, *p.joints_deg[1:]))
    prog.positions[k] = p
    return prog


@settings(max_examples=20, deadline=None, derandomize=True)
@given(program_spec())
def test_the_oracle_catches_a_value_off_by_a_thousandth(spec):
    prog = _perturbed(parse_ls(hand_text(spec), "gen.ls"))
    assert mismatches(spec, prog) != []


def spec_positions(spec: dict) -> dict[int, LSPosition]:
    """The spec as the data model (SI values built here from the integers)."""
    out = {}
    for n, p in spec["positions"].items():
        kw = ({"xyzwpr": tuple(k / 1000 for k in p["cart"]), "config": p["config"]}
              if p["cart"] is not None else {"joints_deg": tuple(k / 1000 for k in p["joints"])})
        groups = ()
        if p["gp2"] is not None:
            g = p["gp2"]
            groups = (LSGroup(2, g["uf"], g["ut"], joints=tuple(si(k, u) for k, u in g["joints"]),
                              joint_units=tuple(u for _, u in g["joints"])),)
        out[n] = LSPosition(n, p["uf"], p["ut"], **kw, ext=tuple(si(k, u) for k, u in p["ext"]),
                            ext_units=tuple(u for _, u in p["ext"]), groups=groups)
    return out


_WRITTEN = re.compile(r"\b([EJ]\d)=\s*(-?\d+\.\d{3})\s*(mm|deg)")


@SETTINGS
@given(program_spec())
def test_write_ls_writes_the_values_and_reads_back_to_them(spec):
    """``write_ls`` of the data model: its text holds each E and GP2 value to three decimals in
    its unit, DEFAULT_GROUP names the groups, and the text parses back to the spec (and to the
    same text again)."""
    motions = [LSMotion(k, ("P", n), 50.0 if k == "J" else 100.0, "%" if k == "J" else "mm/sec",
                        None, options=tuple(f)) for k, n, f in spec["motions"]]
    text = write_ls("GEN", motions, spec_positions(spec))
    mask = re.search(r"DEFAULT_GROUP\s*=\s*([^;]*);", text).group(1).split(",")
    assert [k + 1 for k, e in enumerate(mask) if e == "1"] == list(spec["groups"])
    pos_text = text.split("/POS")[1]
    for n, p in spec["positions"].items():
        block = re.search(rf"P\[{n}\]\{{(.*?)\}};", pos_text, re.S).group(1)
        gp1, _, gp2 = block.partition("GP2:")
        want = [(f"E{j}", dec(k), u) for j, (k, u) in enumerate(p["ext"], 1)]
        assert [w for w in _WRITTEN.findall(gp1) if w[0][0] == "E"] == want
        if p["gp2"] is not None:
            want = [(f"J{j}", dec(k), u) for j, (k, u) in enumerate(p["gp2"]["joints"], 1)]
            assert _WRITTEN.findall(gp2) == want
        else:
            assert not gp2
    prog = parse_ls(text, "w.ls")
    assert mismatches(spec, prog) == []
    assert write_ls("GEN", prog.instructions, prog.positions) == text


def test_a_coordinated_program_as_a_controller_writes_it():
    """A robot with a track (E1, mm) and a 2-axis positioner as GP2, moved with COORD, in the
    layout of controller and offline-programming files (``P[n] {``, `` };``, ``CONFIG:``)."""
    text = """/PROG  COORD1
/ATTR
DEFAULT_GROUP   = 1,1,*,*,*;
/MN
1: L P[1] 240cm/min CNT100 COORD ;
: Arc Start[1];
2: L P[2] 30cm/min CNT100 COORD PTH ;
/POS
P[1] {
    GP1:
        UF : 6, UT : 5,     CONFIG: 'N U T, 0, 0, 0',
       X = 45.4 mm, Y = -124.0 mm, Z = 56.6 mm,
       W = 0.0 deg, P = 0.0 deg, R = 0.0 deg,
       E1=   1500.000  mm
    GP2:
        UF : 1, UT : 2,
       J1 = 90.0 deg, J2 = -30.0 deg
 };
P[2:"end"]{
   GP1:
    UF : 6, UT : 5,
    J1=   -41.180 deg,    J2=   -26.810 deg,    J3=    11.060 deg,
    J4=  -217.400 deg,    J5=    71.740 deg,    J6=    85.790 deg,
    E1=     10.000  mm
   GP2:
     UF : 1, UT : 2,
     J1=     0.000 deg,   J2=   180.000 deg
};
/END
"""
    prog = parse_ls(text, "coord1.ls")
    assert prog.groups == (1, 2) and prog.groups_line == 3
    p1, p2 = prog.positions[1], prog.positions[2]
    assert p1.ext == (1.5,) and p1.ext_units == ("mm",) and p1.ext_kinds == ("prismatic",)
    assert p1.gp2.joints == pytest.approx((math.pi / 2, -math.pi / 6), abs=1e-15)
    assert p1.gp2.joint_kinds == ("revolute", "revolute") and (p1.gp2.uf, p1.gp2.ut) == (1, 2)
    assert p2.joints_deg == (-41.18, -26.81, 11.06, -217.4, 71.74, 85.79)
    assert p2.ext == (0.01,) and p2.gp2.joints == pytest.approx((0.0, math.pi), abs=1e-15)
    m1, m2 = [m for m in prog.instructions if isinstance(m, LSMotion)]
    assert m1.options == ("COORD",) and m1.arc == "start" and m2.options == ("COORD", "PTH")
    # COORD runs (sim.scenario.program); PTH is still a warning
    assert (7, "motion option 'PTH' not simulated") in prog.warnings
    assert not any("COORD" in text for _, text in prog.warnings)


def test_a_program_without_extended_axes_reads_as_before():
    prog = parse_ls(hand_text({"groups": (1,), "style": "fixed", "motions": [("J", 1, [])],
                               "positions": {1: {"uf": 0, "ut": 1, "cart": [1, 2, 3, 4, 5, 6],
                                                 "joints": None, "config": ("N", "U", "T", 0,
                                                                            0, 0),
                                                 "ext": [], "gp2": None}}}), "a.ls")
    p = prog.positions[1]
    assert (p.ext, p.ext_units, p.groups, p.gp2, p.group_numbers) == ((), (), (), None, (1,))
    assert prog.groups == (1,) and "DEFAULT_GROUP\t= 1,*,*,*,*;" in write_ls("A", [], {1: p})


# ------------------------------------------------------------------ hostile text
BASE = {"groups": (1, 2), "style": "fixed", "motions": [("L", 1, ["COORD"]), ("L", 2, [])],
        "positions": {
            1: {"uf": 1, "ut": 1, "cart": [100000, 200000, 300000, 180000, 0, 0], "joints": None,
                "config": ("N", "U", "T", 0, 0, 0), "ext": [(1500000, "mm"), (-45500, "deg")],
                "gp2": {"uf": 1, "ut": 2, "joints": [(90000, "deg"), (-30000, "deg")]}},
            2: {"uf": 1, "ut": 1, "cart": None, "joints": [0, 10000, -20000, 0, 45000, 0],
                "config": ("N", "U", "T", 0, 0, 0), "ext": [(1000, "mm")],
                "gp2": {"uf": 1, "ut": 2, "joints": [(0, "deg"), (250, "mm")]}}}}


def _lines_with(text: str, needle: str) -> list[int]:
    return [i for i, s in enumerate(text.splitlines()) if needle in s]


def _sub_value(name: str, new: str):
    """A corruption: the first ``name=<value>`` of a line replaced by ``new``."""
    def edit(line: str) -> str | None:
        m = re.search(rf"{name}=\s*-?[\d.]+\s*(mm|deg)", line)
        return None if m is None else line[:m.start()] + new + line[m.end():]
    return edit


#: Corruptions of one line of valid E/GP2 text: (name, edit of the line, what the error says).
CORRUPTIONS = [
    ("missing =", _sub_value("E1", "E1   1500.000  mm"), "not a position value"),
    ("unit rad", _sub_value("E1", "E1=   1.000  rad"), "the unit is deg"),
    ("no unit", _sub_value("E1", "E1=   1.000"), "the unit is deg"),
    ("E0", _sub_value("E1", "E0=   1.000  mm"), "E1 .. E9"),
    ("E10", _sub_value("E1", "E10=   1.000  mm"), "E1 .. E9"),
    ("a gap", _sub_value("E1", "E3=   1.000  mm"), "without"),
    ("NaN", _sub_value("E1", "E1=   NaN  mm"), "not a number"),
    ("nan", _sub_value("J1", "J1=   nan  deg"), "not a number"),
    ("1e400", _sub_value("E1", "E1=   1e400  mm"), "not a finite number"),
    ("-1e400", _sub_value("J2", "J2=   -1e400  deg"), "not a finite number"),
    ("duplicate E1", lambda s: s + ",\tE1=   2.000  mm" if "E1=" in s else None, "given twice"),
    ("J9999", _sub_value("J1", "J9999= 1.000 deg"), "J1 .. J9"),
    ("robot joint in mm", lambda s: s.replace(" deg,\tJ2", " mm,\tJ2") if "J3=" in s else None,
     "are in deg"),
    ("quote", lambda s: s.replace("CONFIG : '", "CONFIG : ") if "CONFIG" in s else None,
     "quote"),
]


def _gp(text: str, k: int, number: str) -> str:
    """``GP2:`` of the k-th position renamed."""
    lines = text.splitlines()
    at = _lines_with(text, "GP2:")[k]
    lines[at] = lines[at].replace("GP2:", number)
    return "\n".join(lines) + "\n"


def test_every_corruption_is_one_line_naming_the_corrupted_line():
    base = hand_text(BASE)
    assert parse_ls(base, "base.ls").groups == (1, 2)
    for name, edit, needle in CORRUPTIONS:
        hit = False
        for i, line in enumerate(base.splitlines()):
            new = edit(line)
            if new is None or new == line:
                continue
            hit = True
            lines = base.splitlines()
            lines[i] = new
            with pytest.raises(ScenarioError) as e:
                parse_ls("\n".join(lines) + "\n", "bad.ls")
            msg = str(e.value)
            assert "\n" not in msg and msg.startswith(f"bad.ls: line {i + 1}: "), (name, msg)
            assert needle in msg, (name, msg)
        assert hit, name


@pytest.mark.parametrize("edit,line_of,needle", [
    (lambda t: _gp(t, 0, "GP3:"), lambda t: _lines_with(t, "GP3:")[0],
     "has GP3, but DEFAULT_GROUP (line 4) = 1,1,*,*,* moves GP1, GP2 only"),
    (lambda t: t.replace("1,1,*,*,*", "1,*,*,*,*"), lambda t: _lines_with(t, "GP2:")[0],
     "has GP2, but DEFAULT_GROUP (line 4)"),
    (lambda t: re.sub(r"   GP2:\n[^\n]*\n[^\n]*\n};\n/END", "};\n/END", t),
     lambda t: _lines_with(t, "P[2]{")[0], "P[2] has no GP2, but DEFAULT_GROUP (line 4)"),
    (lambda t: re.sub(r"DEFAULT_GROUP[^\n]*\n", "", t).replace("GP2:", "GP1:", 1),
     lambda t: _lines_with(t, "GP1:")[1], "GP1 is given twice"),
    (lambda t: re.sub(r"   GP2:\n[^\n]*\n[^\n]*\n};\n/END", "};\n/END",
                      re.sub(r"DEFAULT_GROUP[^\n]*\n", "", t)),
     lambda t: _lines_with(t, "P[2]{")[0], "P[2] has no GP2, but P[1] (line"),
    (lambda t: t.replace("1,1,*,*,*", "*,1,*,*,*"), lambda t: 3, "does not move group 1"),
    (lambda t: t.replace("1,1,*,*,*", "1,2,*,*,*"), lambda t: 3, "each 1 (the program moves"),
    (lambda t: t.replace("1,1,*,*,*", "1,1,*,*,*,*,*,*,*"), lambda t: 3, "up to 8 entries"),
    (lambda t: t.replace("/MN", "DEFAULT_GROUP = 1,1,*,*,*;\n/MN"), lambda t: 4,
     "DEFAULT_GROUP is given twice"),
    (lambda t: t.replace("GP2:", "GP9:", 1), lambda t: _lines_with(t, "GP9:")[0], "GP1 .. GP8"),
    (lambda t: t.replace("GP2:", "GP2:\n   GP2:", 1), lambda t: _lines_with(t, "GP2:")[1],
     "GP2 is given twice"),
    (lambda t: t.replace("J1=", "X = 1.0 mm,\tJ1=", 1), lambda t: _lines_with(t, "X = 1.0")[0],
     "both joint"),
    (lambda t: t.replace("\tUF : 1, UT : 2,", "\tUF : 1,", 1), lambda t: _lines_with(t, "GP2:")[0],
     "needs 'UF : n, UT : n' (no UT)"),
])
def test_group_faults_are_one_line_naming_the_line(edit, line_of, needle):
    text = edit(hand_text(BASE))
    with pytest.raises(ScenarioError) as e:
        parse_ls(text, "bad.ls")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"bad.ls: line {line_of(text) + 1}: "), msg
    assert needle in msg, msg


POS_LINE = st.text(alphabet="EJGPXYZWR0123456789=:,.'-+ emdgnaNIF\t", max_size=60)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.data())
def test_any_damage_to_a_position_line_parses_or_is_one_line(data):
    """A /POS line replaced, doubled, dropped or cut: parsed, or one ScenarioError line naming
    the file and a line number; never another exception."""
    lines = hand_text(BASE).splitlines()
    first = lines.index("/POS") + 1
    k = data.draw(st.integers(first, len(lines) - 2), label="line")
    how = data.draw(st.sampled_from(["replace", "double", "drop", "cut"]), label="how")
    if how == "replace":
        lines[k] = data.draw(POS_LINE, label="text")
    elif how == "double":
        lines.insert(k, lines[k])
    elif how == "drop":
        del lines[k]
    else:
        lines[k] = lines[k][:data.draw(st.integers(0, len(lines[k])), label="cut")]
    try:
        parse_ls("\n".join(lines) + "\n", "dmg.ls")
    except ScenarioError as e:
        assert "\n" not in str(e) and re.match(r"dmg\.ls: line \d+: ", str(e)), str(e)


def test_a_huge_line_is_refused_by_its_length():
    text = hand_text(BASE).replace("E1=", "E1=" + "1" * 100_000, 1)
    with pytest.raises(ScenarioError, match=r"line \d+: (P\[1\]: )?a line of 100,0\d\d characters"):
        parse_ls(text, "big.ls")


def test_a_long_value_is_cut_in_the_message():
    text = hand_text(BASE).replace("E1=", "E1=" + "x" * 900 + " ", 1)
    with pytest.raises(ScenarioError) as e:
        parse_ls(text, "long.ls")
    assert len(str(e.value)) < 200 and "..." in str(e.value)


def test_the_program_s_lines_and_warnings_are_bounded():
    from sim.scenario.fanuc_ls import MAX_PROGRAM_LINES, MAX_WARNINGS

    with pytest.raises(ScenarioError, match=rf"line {MAX_PROGRAM_LINES + 1}: more than"):
        parse_ls("/PROG X\n" + "\n" * MAX_PROGRAM_LINES, "many.ls")
    body = "\n".join(f"{k}: DO[1]=ON ;" for k in range(1, 2 * MAX_WARNINGS))
    prog = parse_ls(f"/PROG X\n/MN\n{body}\n/END\n", "w.ls")
    assert len(prog.warnings) == MAX_WARNINGS + 1
    assert "not listed" in prog.warnings[-1][1] and prog.warnings[-2][0] == MAX_WARNINGS + 2


@pytest.mark.parametrize("line", [
    "1: a" + " " * 900 + "b" + " " * 900 + "c",  # the line pattern took cubic time: 17 s
    "1: Weave Sine[" + " " * 1900 + "x",          # the weave pattern: 3 s
    "1: WAIT " + "1" * 1900 + "x",                # a number's digits: quadratic
    "1: L P[1] 100mm/sec FINE " + "a " * 900,     # 900 options
])
def test_lines_built_to_make_the_patterns_backtrack_are_read_at_once(line):
    """Each of these took seconds to match before the patterns were made linear (no clock
    here: a regression shows as a slow test)."""
    try:
        parse_ls(f"/PROG X\n/MN\n{line}\n{line}\n{line}\n/END\n", "slow.ls")
    except ScenarioError as e:
        assert "\n" not in str(e)


def test_a_second_robot_as_gp2_with_its_own_track_reads_and_writes_back():
    """GP2 Cartesian (a second arm) with its CONFIG and an E1 of its own."""
    text = hand_text(BASE).replace(
        "\tUF : 1, UT : 2,\n\tJ1=    90.000  deg,\tJ2=   -30.000  deg",
        "\tUF : 2, UT : 3,\t\tCONFIG : 'F D B, 1, 0, -1',\n"
        "\tX =   1.500 mm,\tY =   -2.250 mm,\tZ =   3.000 mm,\n"
        "\tW =   4.000 deg,\tP =   5.000 deg,\tR =   -6.000 deg,\n\tE1=   -250.500  mm")
    assert "CONFIG : 'F D B" in text
    prog = parse_ls(text, "two.ls")
    g = prog.positions[1].gp2
    assert (g.uf, g.ut, g.joints, g.config) == (2, 3, None, ("F", "D", "B", 1, 0, -1))
    assert g.xyzwpr == (1.5, -2.25, 3.0, 4.0, 5.0, -6.0)
    assert g.ext == (-0.2505,) and g.ext_kinds == ("prismatic",)
    again = parse_ls(write_ls("TWO", prog.instructions, prog.positions), "again.ls")
    assert again.positions[1].gp2 == replace(g, line=again.positions[1].gp2.line)
