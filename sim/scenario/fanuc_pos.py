"""The positions of a FANUC TP program's ``/POS`` section: motion groups and extended axes.

A position ``P[n]{ ... };`` holds one block per motion group, the robot's (``GP1:``) first::

    P[1]{
       GP1:
        UF : 1, UT : 1,     CONFIG : 'N U T, 0, 0, 0',
        X =   100.000  mm,  Y =   200.000  mm,  Z =   300.000  mm,
        W =   180.000 deg,  P =     0.000 deg,  R =     0.000 deg,
        E1=  1500.000  mm
       GP2:
        UF : 1, UT : 2,
        J1=    90.000 deg,  J2=   -30.000 deg
    };

* ``GP1``: its ``UF`` and ``UT``; a Cartesian position (``CONFIG``, ``X, Y, Z`` mm, ``W, P, R``
  deg) or a joint one (``J1 .. Jn`` deg); then the extended axes of the robot's group, ``E1`` ..
  ``E9`` in order, each in ``deg`` (a rotary axis: a positioner's tilt or turn) or ``mm`` (a
  linear one: a track) -- axes integrated in group 1;
* ``GP2`` .. (a positioner, a track or a second robot as a motion group of its own): its ``UF``
  and ``UT``, joint values ``J1 ..`` each in ``deg`` or ``mm``, or a Cartesian position with its
  ``CONFIG``; its own ``E1 ..`` too.

Text before the first ``GPn:`` is GP1's (hand-written files often leave ``GP1:`` out). Values
are separated by commas, one name a value: a name written twice, a missing or other unit
(``rad``), ``E0``/``E10``, a gap (``E1``, ``E3``), a value that is not a finite number, joint
and Cartesian values in one group are one-line errors naming the line.

The program's ``DEFAULT_GROUP = 1,1,*,*,*;`` (``/ATTR``) names the groups its motions move
(:func:`parse_default_group`); every position holds exactly those (:func:`check_groups`).

Units: the extended axes and the joint values of GP2 .. are kept in SI (rad, m) with the unit
each was written in (``deg`` is a revolute axis, ``mm`` a prismatic one: :data:`AXIS_KIND`), so
that :func:`format_position` writes them as they were read; GP1's Cartesian and joint values
stay in the controller's mm and deg (``xyzwpr``, ``joints_deg``), as before.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from sim.errors import ScenarioError

#: Unit of an extended axis or of a joint of GP2 .. -> the kind of axis it is.
AXIS_KIND = {"deg": "revolute", "mm": "prismatic"}

#: Most extended axes of a group (``E1`` .. ``E9``).
MAX_EXT_AXES = 9
#: Most joints of a group (``J1`` .. ``J9``).
MAX_GROUP_JOINTS = 9
#: Highest motion group number read (``GP1`` .. ``GP8``; the ``DEFAULT_GROUP`` mask's length).
MAX_GROUPS = 8
#: Longest line of a position block (a controller writes fewer than 100 characters).
MAX_POS_LINE = 1000

_NUM = re.compile(r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?")
_HEADER = re.compile(r"^GP\s*(\d+)\s*:\s*(.*)$", re.I)
_FRAME = re.compile(r"^(UF|UT)\s*:\s*(\S*)$", re.I)
_CONFIG = re.compile(r"^CONFIG\s*:\s*(.*)$", re.I)
_CONFIG_VALUE = re.compile(r"^'\s*([NF])\s*([UD])?\s*([TB])\s*,\s*(-?\d{1,3})\s*,\s*(-?\d{1,3})\s*,"
                           r"\s*(-?\d{1,3})\s*'$", re.I)
_VALUE = re.compile(r"^([A-Za-z]+)(\d*)\s*=\s*(\S*?)\s*([A-Za-z]*)$")
_ITEM = re.compile(r"(?:[^,']|'[^']*')+")
_CARTESIAN = ("X", "Y", "Z", "W", "P", "R")


def to_si(value: float, unit: str) -> float:
    """A value written in ``unit`` (``"deg"`` / ``"mm"``) in SI: rad / m."""
    return math.radians(value) if unit == "deg" else value / 1000.0


def from_si(value: float, unit: str) -> float:
    """An SI value (rad / m) in ``unit`` (``"deg"`` / ``"mm"``), as written."""
    return math.degrees(value) if unit == "deg" else value * 1000.0


@dataclass(frozen=True)
class LSGroup:
    """A motion group of a position after GP1 (``GP2:`` ..).

    Attributes:
        number: n of ``GPn``. uf, ut: Its user frame and tool numbers.
        joints: Joint values in SI (rad, m), or None for a Cartesian group.
        joint_units: ``"deg"`` / ``"mm"`` for each joint value, as written.
        xyzwpr, config: A Cartesian group's ``(X, Y, Z, W, P, R)`` (mm, deg) and CONFIG (as
            :class:`~sim.scenario.fanuc_pos.LSPosition`'s), or None.
        ext, ext_units: Its extended axes ``E1 ..`` in SI and their units.
        line: Line number of its ``GPn:``.
    """

    number: int
    uf: int
    ut: int
    joints: tuple[float, ...] | None = None
    joint_units: tuple[str, ...] = ()
    xyzwpr: tuple[float, ...] | None = None
    config: tuple | None = None
    ext: tuple[float, ...] = ()
    ext_units: tuple[str, ...] = ()
    line: int = 0

    @property
    def joint_kinds(self) -> tuple[str, ...]:
        """``"revolute"`` / ``"prismatic"`` for each joint value (deg / mm)."""
        return tuple(AXIS_KIND[u] for u in self.joint_units)

    @property
    def ext_kinds(self) -> tuple[str, ...]:
        """``"revolute"`` / ``"prismatic"`` for each extended axis (deg / mm)."""
        return tuple(AXIS_KIND[u] for u in self.ext_units)


@dataclass(frozen=True)
class LSPosition:
    """A position of the /POS section (or a position register given to the scenario).

    Attributes:
        index: n of ``P[n]``. uf, ut: Its user frame and tool numbers (GP1's).
        xyzwpr: ``(X, Y, Z, W, P, R)`` in mm and deg, or None for a joint position.
        config: ``(flip, up, front, turn4, turn5, turn6)``: ``"N"``/``"F"``, ``"U"``/``"D"``,
            ``"T"``/``"B"``, ints; None for a joint position.
        joints_deg: The controller's joint values (deg), or None for a Cartesian position.
        line: Line number of ``P[n]{`` in the file.
        ext: GP1's extended axes ``E1, E2, ..`` in order, in SI (rad for ``deg``, m for ``mm``).
        ext_units: The unit each was written in, ``"deg"`` or ``"mm"`` (:attr:`ext_kinds`).
        groups: The position's other motion groups, GP2 .. in order (:meth:`group`).
    """

    index: int
    uf: int
    ut: int
    xyzwpr: tuple[float, ...] | None = None
    config: tuple | None = None
    joints_deg: tuple[float, ...] | None = None
    line: int = 0
    ext: tuple[float, ...] = ()
    ext_units: tuple[str, ...] = ()
    groups: tuple[LSGroup, ...] = ()

    @property
    def ext_kinds(self) -> tuple[str, ...]:
        """``"revolute"`` / ``"prismatic"`` for each extended axis of GP1 (deg / mm)."""
        return tuple(AXIS_KIND[u] for u in self.ext_units)

    @property
    def group_numbers(self) -> tuple[int, ...]:
        """The motion groups the position holds: ``(1,)``, ``(1, 2)`` .."""
        return (1, *(g.number for g in self.groups))

    def group(self, number: int) -> LSGroup | None:
        """Its group ``GP<number>`` (2 ..), or None when it has none."""
        return next((g for g in self.groups if g.number == number), None)

    @property
    def gp2(self) -> LSGroup | None:
        """Its ``GP2`` group, or None."""
        return self.group(2)


def extended_values(pos: LSPosition) -> tuple[tuple[str, float, str], ...]:
    """A position's values of axes other than GP1's robot joints, in the order a program's
    extended values map onto a cell's external axes: GP1's ``E1 .. En``, then each further
    group's ``J1 .. Jk`` and its own ``E1 ..`` (groups in order); each ``(label, SI value,
    unit)``, the label as the program writes it (``"E2"``, ``"GP2 J1"``). A Cartesian group
    (a second robot) gives no joint values: :func:`cartesian_group` finds it."""
    out = [(f"E{j + 1}", v, u) for j, (v, u) in enumerate(zip(pos.ext, pos.ext_units,
                                                               strict=True))]
    for g in pos.groups:
        if g.joints is not None:
            out += [(f"GP{g.number} J{j + 1}", v, u)
                    for j, (v, u) in enumerate(zip(g.joints, g.joint_units, strict=True))]
        out += [(f"GP{g.number} E{j + 1}", v, u)
                for j, (v, u) in enumerate(zip(g.ext, g.ext_units, strict=True))]
    return tuple(out)


def cartesian_group(pos: LSPosition) -> LSGroup | None:
    """The first of a position's further groups held as a Cartesian position (a second robot),
    or None."""
    return next((g for g in pos.groups if g.joints is None), None)


def _err(path, line: int, text: str) -> ScenarioError:
    return ScenarioError(f"{path}: line {line}: {text}")


def _cut(text: str, n: int = 40) -> str:
    """Text of the file shown in a message: at most ``n`` characters."""
    return text if len(text) <= n else text[:n - 3] + "..."


def _items(text: str, path, ln: int, what: str) -> list[str]:
    """A line's comma-separated items (a quoted CONFIG keeps its commas)."""
    if text.count("'") % 2:
        raise _err(path, ln, f"{what}: a quote (') is not closed: {_cut(text.strip())!r}")
    return [s.strip() for s in _ITEM.findall(text) if s.strip()]


class _Group:
    """The items of one group block as read, each with its line."""

    def __init__(self, number: int, line: int, what: str) -> None:
        self.number, self.line, self.what = number, line, what
        self.frames: dict[str, tuple[int, int]] = {}
        self.config: tuple[tuple, int] | None = None
        self.values: dict[str, tuple[float, str, int]] = {}

    def add(self, item: str, path, ln: int) -> None:
        what = self.what
        mf = _FRAME.match(item)
        if mf:
            key = mf.group(1).upper()
            if key in self.frames:
                raise _err(path, ln, f"{what}: {key} is given twice (line {self.frames[key][1]})")
            if not re.fullmatch(r"\d{1,4}", mf.group(2)):
                raise _err(path, ln, f"{what}: {_cut(item)!r}: {key} is a frame number, "
                           f"'{key} : n'")
            self.frames[key] = (int(mf.group(2)), ln)
            return
        mc = _CONFIG.match(item)
        if mc:
            if self.config is not None:
                raise _err(path, ln, f"{what}: CONFIG is given twice (line {self.config[1]})")
            cv = _CONFIG_VALUE.match(mc.group(1).strip())
            if not cv:
                raise _err(path, ln, f"{what}: {_cut(item)!r}: CONFIG : 'N U T, 0, 0, 0' (flip "
                           "N/F, up/down U/D, front/back T/B, turns of J4, J5, J6)")
            self.config = ((cv.group(1).upper(), (cv.group(2) or "U").upper(),
                            cv.group(3).upper(), int(cv.group(4)), int(cv.group(5)),
                            int(cv.group(6))), ln)
            return
        mv = _VALUE.match(item)
        if not mv:
            raise _err(path, ln, f"{what}: {_cut(item)!r} is not a position value ('NAME = value "
                       "unit', 'UF : n', 'UT : n' or CONFIG : '...')")
        letters, digits, text, unit = mv.group(1).upper(), mv.group(2), mv.group(3), mv.group(4)
        name = _cut(letters + digits, 12)
        if not ((letters in _CARTESIAN and not digits) or (letters in ("J", "E") and digits)):
            raise _err(path, ln, f"{what}: {name} is not a position value (X, Y, Z, W, P, R, "
                       "J1.., E1..)")
        if letters == "E" and not 1 <= int(digits) <= MAX_EXT_AXES:
            raise _err(path, ln, f"{what}: {name}: extended axes are E1 .. E{MAX_EXT_AXES}")
        if letters == "J" and not 1 <= int(digits) <= MAX_GROUP_JOINTS:
            raise _err(path, ln, f"{what}: {name}: joints are J1 .. J{MAX_GROUP_JOINTS}")
        if digits and digits != str(int(digits)):
            raise _err(path, ln, f"{what}: {name}: write it {letters}{int(digits)}")
        if name in self.values:
            raise _err(path, ln, f"{what}: {name} is given twice (line {self.values[name][2]})")
        if not _NUM.fullmatch(text):
            raise _err(path, ln, f"{what}: {name} = {_cut(text)!r}: not a number")
        value = float(text)
        if not math.isfinite(value):
            raise _err(path, ln, f"{what}: {name} = {_cut(text)}: not a finite number")
        unit = unit.lower()
        if letters in ("X", "Y", "Z") and unit not in ("", "mm"):
            raise _err(path, ln, f"{what}: {name} is in mm, not {_cut(unit, 12)!r}")
        if letters in ("W", "P", "R") and unit not in ("", "deg"):
            raise _err(path, ln, f"{what}: {name} is in deg, not {_cut(unit, 12)!r}")
        if letters in ("J", "E") and unit not in AXIS_KIND:
            raise _err(path, ln, f"{what}: {name} = {_cut(text)} {_cut(unit, 12)}: the unit is deg "
                       "(a rotary axis) or mm (a linear one)"
                       + ("" if unit else ", and is not left out"))
        self.values[name] = (value, unit, ln)

    def indexed(self, letter: str, path) -> list[tuple[float, str, int]]:
        """``J``/``E`` values in order of their index, which run 1, 2, .. without a gap."""
        got = sorted((int(k[1:]), v) for k, v in self.values.items() if k[0] == letter)
        for want, (have, v) in enumerate(got, start=1):
            if have != want:
                raise _err(path, v[2], f"{self.what}: {letter}{have} without {letter}{want} "
                           f"({letter} values are numbered 1, 2, .. without a gap)")
        return [v for _, v in got]

    def build(self, path) -> dict:
        """The group's fields (:class:`LSGroup`'s names; GP1's joints in deg)."""
        what = self.what
        for key in ("UF", "UT"):
            if key not in self.frames:
                raise _err(path, self.line, f"{what}: needs 'UF : n, UT : n' (no {key})")
        out: dict = {"uf": self.frames["UF"][0], "ut": self.frames["UT"][0]}
        joints = self.indexed("J", path)
        ext = self.indexed("E", path)
        cart = [k for k in _CARTESIAN if k in self.values]
        if joints and cart:
            raise _err(path, self.values[cart[0]][2], f"{what}: both joint (J1 ..) and Cartesian "
                       f"({cart[0]} ..) values; a position is one or the other")
        if joints:  # a CONFIG beside joint values says nothing more: not kept
            if self.number == 1:
                bad = next((v for v in joints if v[1] != "deg"), None)
                if bad is not None:
                    raise _err(path, bad[2], f"{what}: the robot's joints (J1 ..) are in deg")
                out["joints_deg"] = tuple(v for v, _, _ in joints)
            else:
                out["joints"] = tuple(to_si(v, u) for v, u, _ in joints)
                out["joint_units"] = tuple(u for _, u, _ in joints)
        else:
            for name in _CARTESIAN:
                if name not in self.values:
                    raise _err(path, self.line, f"{what}: no {name} value (a Cartesian position "
                               "needs X, Y, Z mm and W, P, R deg; a joint position J1.. deg)")
            if self.config is None:
                raise _err(path, self.line, f"{what}: no CONFIG : 'N U T, 0, 0, 0' (flip, "
                           "up/down, front/back, turns of J4, J5, J6)")
            out["xyzwpr"] = tuple(self.values[k][0] for k in _CARTESIAN)
            out["config"] = self.config[0]
        out["ext"] = tuple(to_si(v, u) for v, u, _ in ext)
        out["ext_units"] = tuple(u for _, u, _ in ext)
        return out


def parse_position(index: int, block: list[tuple[int, str]], path, line: int) -> LSPosition:
    """The position ``P[index]`` from the lines of its block (``(line number, text)``, between
    ``P[n]{`` at ``line`` and ``};``), module docstring.

    Raises:
        ScenarioError: One line naming the file and the line of the fault.
    """
    where = f"P[{index}]"
    groups: list[_Group] = []
    for ln, raw in block:
        if len(raw) > MAX_POS_LINE:
            raise _err(path, ln, f"{where}: a line of {len(raw):,} characters (a position's "
                       f"lines are short; at most {MAX_POS_LINE:,})")
        text = raw.strip()
        mh = _HEADER.match(text)
        if mh:
            number = int(mh.group(1)) if len(mh.group(1)) <= 3 else 0
            if not 1 <= number <= MAX_GROUPS:
                raise _err(path, ln, f"{where}: GP{_cut(mh.group(1), 6)}: motion groups are GP1 .. "
                           f"GP{MAX_GROUPS}")
            if any(g.number == number for g in groups):
                raise _err(path, ln, f"{where}: GP{number} is given twice")
            if number == 1 and groups:
                raise _err(path, ln, f"{where}: GP1 comes first")
            if groups and number <= groups[-1].number:
                raise _err(path, ln, f"{where}: GP{number} after GP{groups[-1].number} (groups "
                           "come in order)")
            groups.append(_Group(number, ln, f"{where}: GP{number}" if number > 1 else where))
            text = mh.group(2)
        for item in _items(text, path, ln, where):
            if not groups:  # values before any GPn: are GP1's
                groups.append(_Group(1, line, where))
            if groups[0].number != 1:
                raise _err(path, ln, f"{where}: no GP1 (the robot's group comes first)")
            groups[-1].add(item, path, ln)
    if not groups or groups[0].number != 1:
        raise _err(path, line, f"{where}: no GP1 values (UF, UT and a Cartesian or joint "
                   "position)")
    gp1 = groups[0].build(path)
    others = tuple(LSGroup(g.number, line=g.line, **g.build(path)) for g in groups[1:])
    return LSPosition(index, line=line, groups=others, **gp1)


def parse_default_group(text: str, path, ln: int) -> tuple[int, ...]:
    """The motion groups named by ``DEFAULT_GROUP``'s value (``"1,1,*,*,*"`` -> ``(1, 2)``):
    each entry ``1`` (the program moves that group) or ``*`` (it does not); group 1 (the robot)
    must be among them.

    Raises:
        ScenarioError: One line naming the file and line.
    """
    entries = [e.strip() for e in text.split(",")]
    if not 1 <= len(entries) <= MAX_GROUPS or any(e not in ("1", "*") for e in entries):
        raise _err(path, ln, f"DEFAULT_GROUP = {_cut(text.strip())!r}: up to {MAX_GROUPS} "
                   "entries, each 1 (the program moves that group) or * (e.g. 1,1,*,*,*)")
    groups = tuple(k + 1 for k, e in enumerate(entries) if e == "1")
    if 1 not in groups:
        raise _err(path, ln, f"DEFAULT_GROUP = {text.strip()}: the program does not move group 1 "
                   "(the robot); cellsim reads programs that do")
    return groups


def check_groups(positions: dict[int, LSPosition], groups: tuple[int, ...], groups_line: int,
                 path) -> tuple[int, ...]:
    """The program's motion groups, which every position holds: ``groups`` of its
    ``DEFAULT_GROUP`` at ``groups_line``, or without one (``groups_line`` 0) those of its first
    position.

    Raises:
        ScenarioError: A position without one of them, or with another, naming its line.
    """
    def names(numbers) -> str:
        return ", ".join(f"GP{g}" for g in numbers)

    first = None
    for k in sorted(positions, key=lambda k: positions[k].line):
        pos = positions[k]
        have = pos.group_numbers
        if not groups_line and first is None:
            groups, first = have, pos
        if have == groups:
            continue
        src = (f"DEFAULT_GROUP (line {groups_line}) = {format_default_group(groups)}"
               if groups_line else f"P[{first.index}] (line {first.line})")
        extra = [g for g in pos.groups if g.number not in groups]
        if extra:
            raise _err(path, extra[0].line, f"P[{k}] has GP{extra[0].number}, but {src} moves "
                       f"{names(groups)} only")
        missing = [g for g in groups if g not in have]
        raise _err(path, pos.line, f"P[{k}] has no {names(missing)}, but {src} moves "
                   f"{names(groups)}")
    return groups


def format_default_group(groups: tuple[int, ...] | list[int]) -> str:
    """The ``DEFAULT_GROUP`` value naming ``groups`` (``(1, 2)`` -> ``"1,1,*,*,*"``; at least five
    entries, as controllers write it)."""
    n = max(5, *groups)
    return ",".join("1" if k + 1 in groups else "*" for k in range(n))


def _fmt(v: float) -> str:
    """A position value to 3 decimals; a value that rounds to zero is written 0.000, not
    -0.000 (a re-exported imported program showed those)."""
    return f"{round(float(v), 3) + 0.0:10.3f}"


def _axis(name: str, value_si: float, unit: str) -> str:
    v = from_si(value_si, unit)
    return f"{name}= {_fmt(v)}  mm" if unit == "mm" else f"{name}= {_fmt(v)} deg"


def _rows(items: list[str]) -> list[str]:
    """Items three to a line, commas between them and at the ends of all lines but the last."""
    out = []
    for r in range(0, len(items), 3):
        out.append("\t" + ",\t".join(items[r:r + 3]) + ("," if r + 3 < len(items) else ""))
    return out


def _group_lines(uf: int, ut: int, xyzwpr, config, joints: list[str], ext: list[str]) -> list[str]:
    if xyzwpr is None:
        head = [f"\tUF : {uf}, UT : {ut},"]
        values = joints
    else:
        f, u, t, t4, t5, t6 = config
        head = [f"\tUF : {uf}, UT : {ut},\t\tCONFIG : '{f} {u} {t}, {t4}, {t5}, {t6}',"]
        x, y, z, w, p, r = xyzwpr
        values = [f"X = {_fmt(x)}  mm", f"Y = {_fmt(y)}  mm", f"Z = {_fmt(z)}  mm",
                  f"W = {_fmt(w)} deg", f"P = {_fmt(p)} deg", f"R = {_fmt(r)} deg"]
    rows = _rows(values)
    if ext:
        rows[-1] += ","
        rows += _rows(ext)
    return head + rows


def format_position(k: int, p: LSPosition) -> list[str]:
    """The lines of position ``P[k]`` (what :func:`parse_position` reads back: values with
    three decimals in the units they were read in)."""
    L = [f"P[{k}]{{", "   GP1:"]
    ext = [_axis(f"E{j + 1}", v, u) for j, (v, u) in enumerate(zip(p.ext, p.ext_units,
                                                                   strict=True))]
    joints = ([] if p.joints_deg is None else
              [f"J{j + 1}= {_fmt(v)} deg" for j, v in enumerate(p.joints_deg)])
    L += _group_lines(p.uf, p.ut, p.xyzwpr if p.joints_deg is None else None, p.config, joints,
                      ext)
    for g in p.groups:
        L.append(f"   GP{g.number}:")
        gext = [_axis(f"E{j + 1}", v, u) for j, (v, u) in enumerate(zip(g.ext, g.ext_units,
                                                                        strict=True))]
        gj = ([] if g.joints is None else
              [_axis(f"J{j + 1}", v, u) for j, (v, u) in enumerate(zip(g.joints, g.joint_units,
                                                                       strict=True))])
        L += _group_lines(g.uf, g.ut, g.xyzwpr if g.joints is None else None, g.config, gj, gext)
    L.append("};")
    return L


__all__ = ["AXIS_KIND", "MAX_EXT_AXES", "MAX_GROUPS", "MAX_GROUP_JOINTS", "LSGroup", "LSPosition",
           "cartesian_group", "check_groups", "extended_values", "format_default_group",
           "format_position", "from_si",
           "parse_default_group", "parse_position", "to_si"]
