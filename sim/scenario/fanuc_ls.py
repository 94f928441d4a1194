"""FANUC TP programs in their ASCII form (``.LS``): read and write.

What is read (everything else is listed as a warning with its line number, never skipped
silently; a malformed line is a one-line error with its line number):

* ``/PROG name``, ``/ATTR`` (ignored), ``/MN`` (the instructions), ``/POS`` (the positions),
  ``/END``;
* motion: ``J``, ``L`` and ``C`` (circular: ``C P[via]`` then ``: P[end] speed term`` on the
  next line) to ``P[n]`` or ``PR[n]``, with speeds in ``%`` (J), ``mm/sec``, ``cm/min``,
  ``inch/min`` or ``sec`` (the move's time) (L, C), or ``WELD_SPEED``, and ``FINE`` or
  ``CNT0..100``; motion options on the same line or on continuation lines (``: Arc
  Start[6] ;``): ``Arc Start[...]``, ``Arc End[...]`` (others are warnings); the controller's
  form without the closing ``;`` is read too;
* ``Arc Start[...]`` / ``Arc End[...]`` as instructions;
* ArcTool's weave instructions: ``Weave Sine[n]`` (and ``Circle``, ``Figure 8``, ``Sine 2``,
  ``L``) with a weave schedule number ``n``, or with the schedule's values written in
  (``Weave Sine[1.5Hz,2.0mm,0.100s,0.100s]``: frequency, amplitude, right dwell, left dwell; the
  units may be left out); ``Weave End`` and ``Weave End[n]``. The schedule table is a sidecar
  file next to the program, ``<program>.weave.toml`` (:func:`weave_table_path`)::

      [weave_schedules.1]
      frequency_hz = 1.5
      amplitude_mm = 2.0
      dwell_right_s = 0.0
      dwell_left_s = 0.0

  :func:`read_ls` reads it when it is there (:func:`read_weave_schedules`);
* ``UFRAME_NUM = n``, ``UTOOL_NUM = n``; ``WAIT x(sec)`` (and ``WAIT x sec``); comments
  (``!text``) and empty lines (``;``);
* positions: Cartesian (``X, Y, Z`` mm, ``W, P, R`` deg: ``R = Rz(R) Ry(P) Rx(W)``, with
  ``CONFIG : 'N U T, 0, 0, 0'``: flip/no flip, up/down, front (T) / back (B), and the turn
  numbers of J4, J5, J6) or joint (``J1 = ... deg``: the controller's joint convention), with
  their ``UF`` and ``UT``, the extended axes of the robot's group (``E1= .. deg|mm``) and
  further motion groups (``GP2:`` ..): :mod:`sim.scenario.fanuc_pos`;
* ``DEFAULT_GROUP = 1,1,*,*,*;`` (``/ATTR``): the motion groups the program moves, which every
  position holds (``LSProgram.groups``);
* the motion options ``COORD``, ``PTH``, ``Wjnt``, ``INC`` are kept as flags of the motion
  (``LSMotion.options``); ``COORD`` runs (:mod:`sim.scenario.program`: an L or C move that
  moves external axes), the others are warnings while not simulated
  (:data:`UNSIMULATED_OPTIONS`).

:func:`parse_ls` gives a :class:`LSProgram`; :func:`write_ls` writes one, and
:func:`write_weave_schedules` its schedule table.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from pydantic import Field

from sim.core.tomlschema import Strict, load_toml
from sim.errors import ScenarioError
from sim.scenario.fanuc_pos import (
    LSGroup,
    LSPosition,
    check_groups,
    format_default_group,
    format_position,
    parse_default_group,
    parse_position,
)
from sim.scenario.schema import MAX_TCP_SPEED_MM_S


@dataclass(frozen=True)
class LSMotion:
    """One motion instruction.

    Attributes:
        kind: ``"J"``, ``"L"`` or ``"C"``. target: ``("P", n)`` or ``("PR", n)``; via: the
        circular move's via point (C only). speed: The value; unit: ``"%"``, ``"mm/sec"``,
        ``"cm/min"``, ``"inch/min"`` or ``"sec"``. cnt: None for FINE, else 0..100.
        arc: ``"start"`` / ``"end"`` option on the line, or None. line: line number.
        options: The motion options kept as flags, as written canonically, in order:
        ``"COORD"`` (coordinated motion with another group: run), ``"PTH"``, ``"Wjnt"``,
        ``"INC"`` (:data:`FLAG_OPTIONS`); each is also a warning while in
        :data:`UNSIMULATED_OPTIONS`.
    """

    kind: str
    target: tuple[str, int]
    speed: float
    unit: str
    cnt: int | None
    via: tuple[str, int] | None = None
    arc: str | None = None
    line: int = 0
    options: tuple[str, ...] = ()


@dataclass(frozen=True)
class WeaveSchedule:
    """A weave schedule of ArcTool, in the controller's units: frequency (Hz), amplitude (mm),
    the dwells at the right and left extremes (s)."""

    frequency_hz: float
    amplitude_mm: float
    dwell_right_s: float = 0.0
    dwell_left_s: float = 0.0


@dataclass(frozen=True)
class LSWeave:
    """A ``Weave <pattern>[..]`` instruction: the pattern as written (``"Sine"``,
    ``"Circle"``, ``"Figure 8"``, ``"Sine 2"``, ``"L"``) and either a schedule number or the
    schedule's values written in."""

    pattern: str
    schedule: int | None = None
    values: WeaveSchedule | None = None


@dataclass(frozen=True)
class LSOther:
    """A non-motion instruction: ``("uframe", n)``, ``("utool", n)``, ``("wait", seconds)``,
    ``("arc", "start" | "end")``, ``("weave", LSWeave)``, ``("weave_end", n or None)``."""

    what: str
    value: object
    line: int = 0


@dataclass
class LSProgram:
    """A parsed TP program: its name, instructions in order, positions by index, warnings
    (``(line, text)`` for every instruction not run), the weave schedules of its sidecar
    table (``weave_table``: that file, None when there is none), and the motion groups it moves
    (``groups``: its ``DEFAULT_GROUP``'s, at ``groups_line``; without one (``groups_line`` 0),
    those its positions hold), which every position holds."""

    name: str
    instructions: list = field(default_factory=list)
    positions: dict[int, LSPosition] = field(default_factory=dict)
    warnings: list[tuple[int, str]] = field(default_factory=list)
    path: Path | None = None
    weave_schedules: dict[int, WeaveSchedule] = field(default_factory=dict)
    weave_table: Path | None = None
    groups: tuple[int, ...] = (1,)
    groups_line: int = 0


_NUM = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_TARGET = r"(P|PR)\[\s*(\d+)\s*(?::[^\]]*)?\]"
_SPEED = rf"({_NUM}|WELD_SPEED|R\[\s*\d+\s*\])\s*(%|mm/sec|cm/min|inch/min|sec|)"
#: The termination, a word of its own (``CNT5O``, ``FINEE`` are malformed, not CNT5 or FINE
#: with an option).
_TERM = r"(FINE|CNT\s*(\d+))(?=\s|$)"
_MOTION = re.compile(rf"^([JL])\s+{_TARGET}\s+{_SPEED}\s+{_TERM}\s*(.*)$", re.I)
_CIRC1 = re.compile(rf"^C\s+{_TARGET}\s*$", re.I)
_CIRC2 = re.compile(rf"^:\s*{_TARGET}\s+{_SPEED}\s+{_TERM}\s*(.*)$", re.I)
_OPTION = re.compile(r"\s*(?:Arc\s+(Start|End)\s*\[[^\]]*\]|(\S+(?:\[[^\]]*\])?))", re.I)
_ARC = re.compile(r"^Arc\s+(Start|End)\s*\[[^\]]*\]\s*$", re.I)
_FRAME = re.compile(r"^(UFRAME_NUM|UTOOL_NUM)\s*=\s*(\d+)\s*$", re.I)
_WAIT = re.compile(rf"^WAIT\s+({_NUM})\s*\(?\s*sec\s*\)?\s*$", re.I)
_LINE = re.compile(r"^\s*(\d+)\s*:(.*)$")  # its body: stripped, and of one closing ;
#: ArcTool's weave patterns, as the instruction writes them (longest first for the match).
WEAVE_PATTERNS = ("Figure 8", "Sine 2", "Circle", "Sine", "L")
_WEAVE_ALT = "|".join(p.replace(" ", r"\s*") for p in WEAVE_PATTERNS)
_WEAVE = re.compile(rf"^Weave\s+({_WEAVE_ALT})\s*\[(.*)\]\s*$", re.I)
_WEAVE_END = re.compile(r"^Weave\s+End\s*(?:\[\s*(\d+)\s*\])?\s*$", re.I)
#: The values of ``Weave Sine[f, a, r, l]``: name and unit (the unit may be left out).
_WEAVE_VALUES = (("frequency", "Hz"), ("amplitude", "mm"), ("right dwell", "s"),
                 ("left dwell", "s"))
#: Highest weave frequency cellsim runs, Hz (as a scenario's ``[phases.weave]``).
MAX_WEAVE_HZ = 20.0
#: Most motion instructions a program may hold (a long weld program has some hundreds).
MAX_PROGRAM_MOTIONS = 2000
#: Longest line read (a controller's lines are shorter than 256 characters).
MAX_LINE_CHARS = 2000
#: Most lines a program may have (9,999 instructions and their positions fit many times).
MAX_PROGRAM_LINES = 200_000
#: Most warnings listed; one more line says that there were more.
MAX_WARNINGS = 500
#: Motion options kept as flags of :class:`LSMotion` (``options``), by their upper-case form.
FLAG_OPTIONS = {"COORD": "COORD", "PTH": "PTH", "WJNT": "Wjnt", "INC": "INC"}
#: The flags that are still warnings: program.py does not run them (it runs ``COORD``).
UNSIMULATED_OPTIONS = frozenset({"PTH", "Wjnt", "INC"})


def _speed(value: str, unit: str, path, line: int) -> tuple[float, str]:
    """A speed field: a number with its unit, or ``WELD_SPEED`` (the arc schedule's speed:
    unit ``"weld"``); a register speed (``R[n]``) is refused."""
    v = value.upper().replace(" ", "")
    if v == "WELD_SPEED":
        return 0.0, "weld"
    if v.startswith("R["):
        raise _err(path, line, f"speed {value}{unit}: register speeds are not read (numeric "
                   "registers are not in the program); write the speed")
    if not unit:
        raise _err(path, line, f"speed {value}: no unit (%, mm/sec, cm/min, inch/min, sec)")
    return float(value), unit.lower()


def _err(path, line: int, text: str) -> ScenarioError:
    return ScenarioError(f"{path}: line {line}: {text}")


def _warn(warnings: list, line: int, text: str) -> None:
    """A warning, while fewer than :data:`MAX_WARNINGS` are listed (then one saying so)."""
    if len(warnings) < MAX_WARNINGS:
        warnings.append((line, text))
    elif len(warnings) == MAX_WARNINGS:
        warnings.append((line, f"more warnings from this line on are not listed (at most "
                               f"{MAX_WARNINGS})"))


def _options(rest: str, path, line: int, warnings: list,
             flags: list | None = None) -> str | None:
    """The arc option of a motion line (``Arc Start[..]`` / ``Arc End[..]``), and its flags
    (:data:`FLAG_OPTIONS`) appended to ``flags``; any other option is a warning, and so is a
    flag of :data:`UNSIMULATED_OPTIONS`."""
    arc = None
    rest = rest.rstrip()
    at = 0
    while at < len(rest):
        m = _OPTION.match(rest, at)
        at = m.end()
        if m.group(1):
            arc = m.group(1).lower()
            continue
        if re.fullmatch(r"FINE|CNT\d+", m.group(2), re.I):
            raise _err(path, line, f"a second termination {m.group(2)!r} (a motion ends FINE "
                       "or CNTx, once)")
        flag = FLAG_OPTIONS.get(m.group(2).upper())
        if flag is not None and flags is not None and flag not in flags:
            flags.append(flag)
        if flag is None or flag in UNSIMULATED_OPTIONS:
            _warn(warnings, line, f"motion option {m.group(2)!r} not simulated")
    return arc


def parse_ls(text: str, path: str | Path = "<program>") -> LSProgram:
    """Parse a TP program (module docstring).

    Raises:
        ScenarioError: A malformed line (one line: file, line number, what is wrong).
    """
    if text.count("\n") >= MAX_PROGRAM_LINES:
        raise _err(path, MAX_PROGRAM_LINES + 1, f"more than {MAX_PROGRAM_LINES:,} lines (split "
                   "the program)")
    lines = text.removeprefix("\ufeff").splitlines()  # a Windows editor's byte-order mark
    prog = LSProgram(name="", path=Path(path))
    section = None
    i = 0
    pending_circ: tuple[tuple[str, int], int] | None = None
    while i < len(lines):
        raw = lines[i]
        ln = i + 1
        if len(raw) > MAX_LINE_CHARS:
            raise _err(path, ln, f"a line of {len(raw):,} characters (at most {MAX_LINE_CHARS:,}; "
                       "a TP program's lines are short)")
        s = raw.strip()
        i += 1
        if not s:
            continue
        if s.upper().startswith("/PROG"):  # headers in any case, as the instructions
            prog.name = s.split(None, 1)[1].split()[0] if len(s.split()) > 1 else ""
            section = "prog"
            continue
        if s.startswith("/"):
            key = s.split()[0].upper()
            if key not in ("/ATTR", "/MN", "/POS", "/END", "/APPL", "/APPL_END"):
                _warn(prog.warnings, ln, f"section {key} not read")
            section = key
            continue
        if section == "/MN":
            m = _LINE.match(raw)
            if m:
                body = m.group(2).strip()
                body = body[:-1].rstrip() if body.endswith(";") else body
            elif s.startswith(":"):  # a circular move's second line, or options continued
                body = s.rstrip(";").strip()
            else:
                raise _err(path, ln, f"not an instruction line ('  n: ... ;'): {s!r}")
            if pending_circ is not None:
                mc = _CIRC2.match(body)
                if not mc:
                    raise _err(path, ln, "a circular move's second line (': P[n] speed FINE|CNT') "
                               f"expected, got {body!r}")
                via, cline = pending_circ
                pending_circ = None
                speed, unit = _speed(mc.group(3), mc.group(4), path, ln)
                cnt = None if mc.group(5).upper() == "FINE" else int(mc.group(6))
                flags: list[str] = []
                arc = _options(mc.group(7), path, ln, prog.warnings, flags)
                prog.instructions.append(LSMotion(
                    "C", (mc.group(1).upper(), int(mc.group(2))), speed, unit, cnt, via=via,
                    arc=arc, line=cline, options=tuple(flags)))
                _check_motion(prog.instructions[-1], path, ln)
                continue
            if not body or body.startswith("!") or body.startswith("//"):
                continue
            if body.startswith(":"):  # a motion's options continued on the next line
                last = prog.instructions[-1] if prog.instructions else None
                if not isinstance(last, LSMotion):
                    raise _err(path, ln, f"a continuation line ({body!r}) after no motion")
                from dataclasses import replace

                flags = list(last.options)
                arc = _options(body[1:], path, ln, prog.warnings, flags)
                prog.instructions[-1] = replace(last, arc=last.arc if arc is None else arc,
                                                options=tuple(flags))
                continue
            mm = _MOTION.match(body)
            if mm:
                kind = mm.group(1).upper()
                speed, unit = _speed(mm.group(4), mm.group(5), path, ln)
                cnt = None if mm.group(6).upper() == "FINE" else int(mm.group(7))
                flags = []
                arc = _options(mm.group(8), path, ln, prog.warnings, flags)
                mo = LSMotion(kind, (mm.group(2).upper(), int(mm.group(3))), speed, unit, cnt,
                              arc=arc, line=ln, options=tuple(flags))
                _check_motion(mo, path, ln)
                prog.instructions.append(mo)
                continue
            mc = _CIRC1.match(body)
            if mc:
                pending_circ = ((mc.group(1).upper(), int(mc.group(2))), ln)
                continue
            bad = re.match(rf"^[JL]\s+{_TARGET}\s+{_SPEED}\s+(\S+)", body, re.I)
            if bad:
                raise _err(path, ln, f"motion termination {bad.group(5)!r} in {body!r}: FINE or "
                           "CNTx expected (x from 0 to 100)")
            if re.match(r"^[JLC]\s", body):
                raise _err(path, ln, f"malformed motion instruction {body!r} (expected e.g. "
                           "'L P[2] 100mm/sec FINE' or 'J P[1] 50% CNT50')")
            ma = _ARC.match(body)
            if ma:
                prog.instructions.append(LSOther("arc", ma.group(1).lower(), ln))
                continue
            mwe = _WEAVE_END.match(body)
            if mwe:
                prog.instructions.append(LSOther(
                    "weave_end", None if mwe.group(1) is None else int(mwe.group(1)), ln))
                continue
            mwv = _WEAVE.match(body)
            if mwv:
                prog.instructions.append(LSOther("weave", _weave(mwv, path, ln), ln))
                continue
            mf = _FRAME.match(body)
            if mf:
                what = "uframe" if mf.group(1).upper() == "UFRAME_NUM" else "utool"
                prog.instructions.append(LSOther(what, int(mf.group(2)), ln))
                continue
            mw = _WAIT.match(body)
            if mw:
                if float(mw.group(1)) < 0:
                    raise _err(path, ln, f"WAIT {mw.group(1)} sec: a time is >= 0")
                prog.instructions.append(LSOther("wait", float(mw.group(1)), ln))
                continue
            _warn(prog.warnings, ln, f"instruction not simulated: {body}")
            continue
        if section == "/POS":
            m = re.match(r"^P\[\s*(\d+)\s*(?::[^\]]*)?\]\s*\{\s*$", s, re.I)
            if not m:
                raise _err(path, ln, f"a position ('P[n]{{') expected, got {s!r}")
            block = []
            start = ln
            while i < len(lines) and not lines[i].strip().startswith("};"):
                block.append((i + 1, lines[i]))
                i += 1
            if i >= len(lines):
                raise _err(path, start, f"P[{m.group(1)}]: no closing '}};'")
            i += 1
            if int(m.group(1)) in prog.positions:
                raise _err(path, start, f"P[{m.group(1)}] is already defined (line "
                           f"{prog.positions[int(m.group(1))].line})")
            prog.positions[int(m.group(1))] = parse_position(int(m.group(1)), block, path,
                                                             start)
            continue
        if section in ("prog", "/ATTR", "/APPL"):
            mg = re.match(r"^DEFAULT_GROUP\s*=\s*([^;]*);?\s*$", s, re.I)
            if mg and section != "/APPL":
                if prog.groups_line:
                    raise _err(path, ln, f"DEFAULT_GROUP is given twice (line {prog.groups_line})")
                prog.groups = parse_default_group(mg.group(1), path, ln)
                prog.groups_line = ln
            continue
        if section == "/END":
            break
        raise _err(path, ln, f"text outside a section: {s!r}")
    if pending_circ is not None:
        raise _err(path, pending_circ[1], "a circular move without its second line")
    motions = [ins for ins in prog.instructions if isinstance(ins, LSMotion)]
    if len(motions) > MAX_PROGRAM_MOTIONS:
        raise _err(path, motions[MAX_PROGRAM_MOTIONS].line,
                   f"the program has {len(motions):,} motion instructions, more than "
                   f"{MAX_PROGRAM_MOTIONS:,} (planning takes about 0.1 s of CPU per blended "
                   "move); split it into several programs")
    if not prog.name:
        raise _err(path, 1, "no /PROG line (is this a TP program in ASCII form?)")
    prog.groups = check_groups(prog.positions, prog.groups, prog.groups_line, path)
    return prog


def _weave(m: re.Match, path, ln: int) -> LSWeave:
    """A ``Weave <pattern>[..]`` instruction: a schedule number, or the four values written in
    (frequency Hz, amplitude mm, right and left dwell s); a register argument is refused."""
    written = " ".join(m.group(1).split())
    pattern = next(p for p in WEAVE_PATTERNS if p.replace(" ", "").lower()
                   == written.replace(" ", "").lower())
    arg = m.group(2).strip()
    what = f"Weave {pattern}[{arg}]"
    if re.fullmatch(r"\d+", arg):
        if int(arg) < 1:
            raise _err(path, ln, f"{what}: weave schedules are numbered from 1")
        return LSWeave(pattern, schedule=int(arg))
    if arg.upper().startswith("R["):
        raise _err(path, ln, f"{what}: a register schedule number is not read (numeric "
                   "registers are not in the program); write the number")
    parts = [x.strip() for x in arg.split(",")]
    if len(parts) != len(_WEAVE_VALUES):
        raise _err(path, ln, f"{what}: a schedule number or 4 values (frequency Hz, amplitude "
                   f"mm, right dwell s, left dwell s), got {len(parts)}")
    values = []
    for text, (name, unit) in zip(parts, _WEAVE_VALUES, strict=True):
        mv = re.fullmatch(rf"({_NUM})\s*([A-Za-z]*)", text)
        units = (unit.lower(), "sec") if unit == "s" else (unit.lower(),)
        if not mv or (mv.group(2) and mv.group(2).lower() not in units):
            raise _err(path, ln, f"{what}: the {name} is a number in {unit}, got {text!r}")
        values.append(float(mv.group(1)))
    freq, amp, right, left = values
    if not 0.0 < freq <= MAX_WEAVE_HZ:
        raise _err(path, ln, f"{what}: frequency {freq:g} Hz: 0 < f <= {MAX_WEAVE_HZ:g}")
    if not amp > 0.0:
        raise _err(path, ln, f"{what}: amplitude {amp:g} mm: must be > 0")
    if right < 0.0 or left < 0.0:
        raise _err(path, ln, f"{what}: a dwell is >= 0 s")
    return LSWeave(pattern, values=WeaveSchedule(freq, amp, right, left))


def _check_motion(mo: LSMotion, path, ln: int) -> None:
    if mo.unit == "weld":
        if mo.kind == "J":
            raise _err(path, ln, "WELD_SPEED on a J move (J speeds are in %)")
        return
    if mo.kind == "J" and mo.unit != "%" and mo.unit != "sec":
        raise _err(path, ln, f"a J move's speed is in % (or sec), not {mo.unit}")
    if mo.kind in ("L", "C") and mo.unit == "%":
        raise _err(path, ln, f"an {mo.kind} move's speed is in mm/sec, cm/min, inch/min or sec, "
                   "not %")
    if not mo.speed > 0:
        raise _err(path, ln, f"speed {mo.speed:g} {mo.unit}: must be > 0")
    if mo.unit == "%" and mo.speed > 100:
        raise _err(path, ln, f"speed {mo.speed:g} %: at most 100")
    mm_s = mo.speed * {"mm/sec": 1.0, "cm/min": 10.0 / 60.0, "inch/min": 25.4 / 60.0}.get(
        mo.unit, 0.0)
    if mm_s > MAX_TCP_SPEED_MM_S:
        raise _err(path, ln, f"speed {mo.speed:g} {mo.unit}: at most "
                   f"{MAX_TCP_SPEED_MM_S:g} mm/sec (a tool point's speed)")
    if mo.cnt is not None and not 0 <= mo.cnt <= 100:
        raise _err(path, ln, f"CNT{mo.cnt}: 0..100")


def read_ls(path: str | Path) -> LSProgram:
    """:func:`parse_ls` of a file (one-line error for a missing or unreadable file), with the
    weave schedules of its sidecar table when there is one (:func:`weave_table_path`)."""
    from sim.core.files import read_input_text

    path = Path(path)
    text = read_input_text(path, ScenarioError, "TP program", errors="replace")
    prog = parse_ls(text, path)
    table = weave_table_path(path)
    if table.is_file():
        prog.weave_schedules = read_weave_schedules(table)
        prog.weave_table = table
    return prog


def weave_table_path(program: str | Path) -> Path:
    """The weave schedule table of a program: ``prog.ls`` -> ``prog.weave.toml`` beside it.

    A sidecar rather than a scenario key: on the controller the schedules are data of the
    controller, not of the program, and ``cellsim export`` writes a program and its table as a
    pair that any scenario naming the program runs as written."""
    return Path(program).with_suffix(".weave.toml")


class _ScheduleSpec(Strict):
    frequency_hz: float = Field(gt=0, le=MAX_WEAVE_HZ)
    amplitude_mm: float = Field(gt=0)
    dwell_right_s: float = Field(0.0, ge=0)
    dwell_left_s: float = Field(0.0, ge=0)


class _WeaveTableSpec(Strict):
    weave_schedules: dict[str, _ScheduleSpec]


def read_weave_schedules(path: str | Path) -> dict[int, WeaveSchedule]:
    """The schedules of a weave table file (module docstring), by number.

    Raises:
        ScenarioError: One line naming the file and the key.
    """
    path = Path(path)
    spec, _ = load_toml(path, _WeaveTableSpec, ScenarioError)
    out = {}
    for key, s in spec.weave_schedules.items():
        if not key.isdigit() or int(key) < 1:
            raise ScenarioError(f"{path}: weave_schedules.{key}: schedule numbers are 1, 2, ...")
        out[int(key)] = WeaveSchedule(s.frequency_hz, s.amplitude_mm, s.dwell_right_s,
                                      s.dwell_left_s)
    return out


def write_weave_schedules(schedules: dict[int, WeaveSchedule], program: str) -> str:
    """The weave table file of ``schedules`` (what :func:`read_weave_schedules` reads)."""
    L = [f"# Weave schedules of {program} (ArcTool's weave schedule table): Weave Sine[n] "
         "runs schedule n", ""]
    for k in sorted(schedules):
        s = schedules[k]
        L += [f"[weave_schedules.{k}]", f"frequency_hz = {s.frequency_hz!r}",
              f"amplitude_mm = {s.amplitude_mm!r}", f"dwell_right_s = {s.dwell_right_s!r}",
              f"dwell_left_s = {s.dwell_left_s!r}", ""]
    return "\n".join(L)


def write_ls(name: str, instructions: list, positions: dict[int, LSPosition],
             comment: str = "") -> str:
    """A TP program in ASCII form (what :func:`parse_ls` reads): positions with their
    extended axes and motion groups (:func:`~sim.scenario.fanuc_pos.format_position`), and
    ``DEFAULT_GROUP`` naming the groups they hold.

    Raises:
        ScenarioError: Positions that do not all hold the same motion groups.
    """
    groups = (1,)
    for i, k in enumerate(sorted(positions)):
        have = positions[k].group_numbers
        if i and have != groups:
            raise ScenarioError(f"write_ls {name}: P[{k}] holds groups {have} but "
                                f"P[{min(positions)}] {groups}; every position of a program "
                                "holds the same groups")
        groups = have
    L = [f"/PROG  {name.upper()}", "/ATTR", f'COMMENT\t\t= "{comment[:16]}";',
         "PROG_SIZE\t= 0;", "FILE_NAME\t= ;", "VERSION\t\t= 0;",
         f"LINE_COUNT\t= {len(instructions)};", "MEMORY_SIZE\t= 0;", "PROTECT\t\t= READ_WRITE;",
         f"DEFAULT_GROUP\t= {format_default_group(groups)};", "/MN"]
    n = 0

    def add(text: str) -> None:
        nonlocal n
        n += 1
        L.append(f"{n:4d}:  {text} ;")

    for ins in instructions:
        if isinstance(ins, LSMotion):
            term = "FINE" if ins.cnt is None else f"CNT{ins.cnt}"
            speed = f"{ins.speed:g}{ins.unit}"
            arc = "" if ins.arc is None else f" Arc {'Start' if ins.arc == 'start' else 'End'}[1]"
            arc = "".join(f" {o}" for o in ins.options) + arc
            tgt = f"{ins.target[0]}[{ins.target[1]}]"
            if ins.kind == "C":
                add(f"C {ins.via[0]}[{ins.via[1]}]")
                L.append(f"    :  {tgt} {speed} {term}{arc} ;")
            else:
                add(f"{ins.kind} {tgt} {speed} {term}{arc}")
        elif ins.what == "uframe":
            add(f"UFRAME_NUM={ins.value}")
        elif ins.what == "utool":
            add(f"UTOOL_NUM={ins.value}")
        elif ins.what == "wait":
            add(f"WAIT {float(ins.value):.3f}(sec)")
        elif ins.what == "arc":
            add(f"Arc {'Start' if ins.value == 'start' else 'End'}[1]")
        elif ins.what == "weave":  # by schedule number (the table: write_weave_schedules)
            add(f"Weave {ins.value.pattern}[{ins.value.schedule}]")
        elif ins.what == "weave_end":
            add("Weave End" if ins.value is None else f"Weave End[{ins.value}]")
        elif ins.what == "comment":
            add(f"!{ins.value}")
    L.append("/POS")
    for k in sorted(positions):
        L += format_position(k, positions[k])
    L.append("/END")
    return "\n".join(L) + "\n"


__all__ = ["FLAG_OPTIONS", "MAX_LINE_CHARS", "MAX_PROGRAM_MOTIONS", "MAX_WEAVE_HZ",
           "UNSIMULATED_OPTIONS", "WEAVE_PATTERNS", "LSGroup", "LSMotion", "LSOther", "LSPosition",
           "LSProgram", "LSWeave", "WeaveSchedule", "parse_ls", "read_ls", "read_weave_schedules",
           "weave_table_path", "write_ls", "write_weave_schedules"]
