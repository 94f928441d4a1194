"""Actuator catalogues: servo motors and reducers read from TOML files.

A catalogue file holds ``[[motors]]`` and ``[[reducers]]`` tables (keys below, SI units named in
the keys). The shipped starter catalogue is ``models/catalog/starter.toml``; a user's own file
is given with ``cellsim size --catalog F`` or the scenario's ``[sizing] catalog`` key. Every
entry cites its ``source`` (the datasheet and the table it was read from); an entry without a
source is marked ``illustrative`` and reports say so.

``[[motors]]``: ``id``, ``rated_torque_nm`` (continuous, S1), ``peak_torque_nm``,
``max_speed_rpm``, ``rotor_inertia_kg_m2``, ``mass_kg`` (optional where the datasheet does not
give it: such an entry ranks last by mass), ``source``; optional ``maker``,
``series``, ``rated_speed_rpm``, ``thermal_time_constant_s``, ``torque_speed`` (the peak
torque-speed curve as ``[[speed_rpm, torque_nm], ...]``, speeds increasing) and
``illustrative``.

``[[reducers]]``: ``id``, ``ratio``, ``rated_torque_nm`` (at ``rated_input_speed_rpm`` for
``rated_life_h``), ``repeated_peak_torque_nm``, ``momentary_peak_torque_nm``, ``efficiency``,
``input_inertia_kg_m2``, ``max_input_speed_rpm``, ``mass_kg`` (optional, as for motors),
``source``; optional ``maker``,
``series``, ``efficiency_note``, ``illustrative``, ``average_torque_limit_nm`` (the "limit for
average torque" of strain-wave gear catalogues: the cycle's average load torque must stay under
it), ``max_average_input_speed_rpm`` (the "limit for average input speed") and
``life_exponent`` (the torque exponent of the maker's life formula: 3 for strain-wave gears,
the default; 10/3 for cycloidal and RV reducers).

Every number is read by the one rule of :mod:`sim.core.tomlschema`: a number (``true`` is not
1 N m, ``"5"`` is not 5), finite, in its physical range (torques 1e-6 to 1e6 N m, speeds 1e-3
to 1e6 rpm, inertias up to 100 kg m^2 (a rotor's > 0), masses 1e-6 to 1e5 kg, efficiencies
0.01 to 1, ratios above 1 up to 1e4, rated lives 1 to 1e7 h, thermal time constants 1e-3 to
1e6 s, life exponents 1 to 10; a torque-speed point's speed and torque 0 to 1e6).

A catalogue holds at most :data:`MAX_PAIRS` motor x reducer pairs (motors times reducers):
the selection checks every pair on every joint, about 0.1 ms and 2.5 kB of memory each, and
lists every passing pair in ``selection.json`` and ``.csv``. At the limit a short six-axis run
with the selection took 29 CPU s and 0.8 GB; 1000 motors x 1000 reducers ran out of an 8 GiB
memory limit after 474 CPU s (about 12 min and 15 GB extrapolated from 300 x 300), so a larger
catalogue is refused when it is read, before its entries are validated.

Mistakes are reported as one line naming the file, the entry (``motors[3]`` and its id) and
the key, with the valid keys where a key is unknown.
"""

from __future__ import annotations

import difflib
import itertools
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from sim.core.resources import models_dir
from sim.core.tomlschema import (
    EFFICIENCY,
    LIFE_H,
    MASS_KG,
    SPEED_RPM,
    TIME_CONSTANT_S,
    TORQUE_NM,
    Columns,
    Quantity,
    Real,
    format_loc,
)
from sim.errors import CatalogError

#: The most motor x reducer pairs a catalogue may give (module docstring): 200 motors and
#: 200 reducers, or 2000 motors and 20 reducers.
MAX_PAIRS = 40_000
#: A reducer's ratio (above 1: checked with the entry).
REDUCER_RATIO = Quantity("a reducer ratio", "", 1.0, 1e4, lo_open=True)
#: A motor's rotor inertia (a motor has one).
MOTOR_INERTIA_KG_M2 = Quantity("a rotor inertia", "kg m^2", 1e-12, 100.0)
#: A reducer's inertia at its input (0: none given).
INPUT_INERTIA_KG_M2 = Quantity("an input inertia", "kg m^2", 0.0, 100.0)
#: The torque exponent of a reducer maker's life formula.
LIFE_EXPONENT = Quantity("a life exponent", "", 1.0, 10.0)
#: The columns of a motor's ``torque_speed`` points: ``[speed_rpm, torque_nm]``.
CURVE_COLUMNS = Columns((Quantity("a motor speed", "rpm", 0.0, 1e6),
                         Quantity("a torque", "N m", 0.0, 1e6)))


def starter_catalog() -> Path:
    """The shipped starter catalogue (``models/catalog/starter.toml``)."""
    return models_dir() / "catalog" / "starter.toml"


class _Entry(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


class MotorSpec(_Entry):
    """A servo motor (catalogue data, SI units)."""

    id: str = Field(min_length=1)
    maker: str = ""
    series: str = ""
    rated_torque_nm: TORQUE_NM.type
    peak_torque_nm: TORQUE_NM.type
    rated_speed_rpm: SPEED_RPM.type | None = None
    max_speed_rpm: SPEED_RPM.type
    rotor_inertia_kg_m2: MOTOR_INERTIA_KG_M2.type
    mass_kg: MASS_KG.type | None = None
    thermal_time_constant_s: TIME_CONSTANT_S.type | None = None
    torque_speed: Annotated[list[list[Real]], CURVE_COLUMNS] | None = None
    source: str = ""
    illustrative: bool = False

    @model_validator(mode="after")
    def _consistent(self) -> MotorSpec:
        if self.rated_torque_nm > self.peak_torque_nm:
            raise ValueError(f"rated_torque_nm {self.rated_torque_nm:g} is above "
                             f"peak_torque_nm {self.peak_torque_nm:g}")
        if self.rated_speed_rpm is not None and self.rated_speed_rpm > self.max_speed_rpm:
            raise ValueError(f"rated_speed_rpm {self.rated_speed_rpm:g} is above "
                             f"max_speed_rpm {self.max_speed_rpm:g}")
        if self.torque_speed is not None:
            pts = self.torque_speed
            for i, row in enumerate(pts):
                if len(row) != 2:
                    raise ValueError(f"torque_speed[{i}]: {len(row)} values; a point is "
                                     "[speed_rpm, torque_nm]")
                for j, (value, quantity) in enumerate(zip(row, CURVE_COLUMNS.quantities,
                                                          strict=True)):
                    bad = quantity.problem(value)
                    if bad:
                        raise ValueError(f"torque_speed[{i}][{j}]: {bad}")
            if len(pts) < 2 or any(b[0] <= a[0] for a, b in itertools.pairwise(pts)):
                raise ValueError("torque_speed needs at least two [speed_rpm, torque_nm] points "
                                 "with increasing speeds")
            if any(s < 0 or t < 0 for s, t in pts):
                raise ValueError("torque_speed points must be >= 0")
        return self


class ReducerSpec(_Entry):
    """A precision reducer (catalogue data, SI units, torques at the output)."""

    id: str = Field(min_length=1)
    maker: str = ""
    series: str = ""
    ratio: REDUCER_RATIO.type
    rated_torque_nm: TORQUE_NM.type
    rated_input_speed_rpm: SPEED_RPM.type
    rated_life_h: LIFE_H.type
    repeated_peak_torque_nm: TORQUE_NM.type
    momentary_peak_torque_nm: TORQUE_NM.type
    efficiency: EFFICIENCY.type
    efficiency_note: str = ""
    input_inertia_kg_m2: INPUT_INERTIA_KG_M2.type
    max_input_speed_rpm: SPEED_RPM.type
    mass_kg: MASS_KG.type | None = None
    average_torque_limit_nm: TORQUE_NM.type | None = None
    max_average_input_speed_rpm: SPEED_RPM.type | None = None
    life_exponent: LIFE_EXPONENT.type = 3.0
    source: str = ""
    illustrative: bool = False

    @model_validator(mode="after")
    def _consistent(self) -> ReducerSpec:
        if not (self.rated_torque_nm <= self.repeated_peak_torque_nm
                <= self.momentary_peak_torque_nm):
            raise ValueError("torques must satisfy rated_torque_nm <= repeated_peak_torque_nm "
                             f"<= momentary_peak_torque_nm, got {self.rated_torque_nm:g}, "
                             f"{self.repeated_peak_torque_nm:g}, "
                             f"{self.momentary_peak_torque_nm:g}")
        return self


@dataclass(frozen=True)
class _Item:
    """A catalogue entry: its validated spec, and whether it cites a source."""

    spec: Any

    @property
    def id(self) -> str:
        return self.spec.id

    @property
    def illustrative(self) -> bool:
        """True when the entry says so or cites no source."""
        return self.spec.illustrative or not self.spec.source.strip()


@dataclass(frozen=True)
class Motor(_Item):
    """A motor of a catalogue (:class:`MotorSpec`)."""

    spec: MotorSpec

    def peak_torque_at(self, speed_rpm: Any) -> Any:
        """Peak torque available at a motor speed, N m: the catalogue curve where given (linear
        between its points, flat before the first, zero past the last and past the maximum
        speed), else the flat peak torque up to the maximum speed."""
        import numpy as np

        n = np.abs(np.asarray(speed_rpm, dtype=float))
        if self.spec.torque_speed is None:
            out = np.full(n.shape, self.spec.peak_torque_nm)
        else:
            s, t = (np.array(x, dtype=float) for x in zip(*self.spec.torque_speed))
            out = np.interp(n, s, t, left=t[0], right=0.0)
        return np.where(n <= self.spec.max_speed_rpm * (1 + 1e-9), out, 0.0)


@dataclass(frozen=True)
class Reducer(_Item):
    """A reducer of a catalogue (:class:`ReducerSpec`)."""

    spec: ReducerSpec


@dataclass(frozen=True)
class Catalog:
    """Motors and reducers read from one or more catalogue files."""

    motors: tuple[Motor, ...]
    reducers: tuple[Reducer, ...]
    sources: tuple[str, ...]

    @property
    def name(self) -> str:
        return ", ".join(Path(s).name for s in self.sources)


_TOP_KEYS = ("catalog", "motors", "reducers")


def load_catalog(path: str | Path) -> Catalog:
    """Read and validate a catalogue file.

    Raises:
        CatalogError: Missing or unreadable file, bad TOML, an unknown or missing key, a bad
            value or inconsistent torques; the message names the file, entry and key.
    """
    path = Path(path)
    where = str(path)
    from sim.core.files import read_input_text

    text = read_input_text(path, CatalogError, "catalogue file")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CatalogError(f"{where}: not valid TOML: {exc}") from None
    unknown = sorted(set(raw) - set(_TOP_KEYS))
    if unknown:
        raise CatalogError(f"{where}: unknown key {unknown[0]!r}; valid keys: "
                           f"{', '.join(_TOP_KEYS)}")
    # the size first: a catalogue too large to select from is refused before it is validated
    _check_pairs(*(len(raw[k]) if isinstance(raw.get(k), list) else 0
                   for k in ("motors", "reducers")), where)
    motors = tuple(Motor(s) for s in _entries(raw, "motors", MotorSpec, where))
    reducers = tuple(Reducer(s) for s in _entries(raw, "reducers", ReducerSpec, where))
    if not motors and not reducers:
        raise CatalogError(f"{where}: the catalogue has no [[motors]] and no [[reducers]]")
    return Catalog(motors, reducers, (where,))


def merge(catalogs: list[Catalog]) -> Catalog:
    """One catalogue of several files' entries (ids must stay unique).

    Raises:
        CatalogError: An id appears in two files.
    """
    _check_pairs(sum(len(c.motors) for c in catalogs), sum(len(c.reducers) for c in catalogs),
                 ", ".join(s for c in catalogs for s in c.sources))
    seen: dict[str, str] = {}
    for cat in catalogs:
        for e in (*cat.motors, *cat.reducers):
            if e.id in seen and seen[e.id] != cat.sources[0]:
                raise CatalogError(f"{cat.sources[0]}: id {e.id!r} is also in {seen[e.id]}")
            seen[e.id] = cat.sources[0]
    return Catalog(tuple(m for c in catalogs for m in c.motors),
                   tuple(r for c in catalogs for r in c.reducers),
                   tuple(s for c in catalogs for s in c.sources))


def _check_pairs(motors: int, reducers: int, where: str) -> None:
    """Refuse a catalogue of more than :data:`MAX_PAIRS` motor x reducer pairs."""
    if motors * reducers > MAX_PAIRS:
        raise CatalogError(f"{where}: {motors} motors x {reducers} reducers = "
                           f"{motors * reducers:,} pairs, more than the {MAX_PAIRS:,} a "
                           "catalogue may give (the selection checks every pair on every "
                           "joint): split it, or keep the candidates of the joints' size")


def _entries(raw: dict[str, Any], key: str, model: type[BaseModel], where: str) -> list[Any]:
    items = raw.get(key, [])
    if not isinstance(items, list):
        raise CatalogError(f"{where}: {key} must be an array of tables ([[{key}]])")
    out, ids = [], set()
    for i, item in enumerate(items):
        label = f"{key}[{i}]"
        if isinstance(item, dict) and isinstance(item.get("id"), str):
            label += f" ({item['id']})"
        if not isinstance(item, dict):
            raise CatalogError(f"{where}: {label}: must be a table")
        try:
            entry = model.model_validate(item)
        except ValidationError as exc:
            raise CatalogError(f"{where}: {label}: {_describe(exc, model)}") from None
        if entry.id in ids:
            raise CatalogError(f"{where}: {label}: id {entry.id!r} appears twice")
        ids.add(entry.id)
        out.append(entry)
    return out


def _describe(exc: ValidationError, model: type[BaseModel]) -> str:
    err = min(exc.errors(include_url=False), key=lambda e: e["type"] != "extra_forbidden")
    key = format_loc(tuple(err["loc"])) if err["loc"] else "(entry)"
    if err["type"] == "extra_forbidden":
        valid = sorted(model.model_fields)
        close = difflib.get_close_matches(key, valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{key}: unknown key{hint}; valid keys: {', '.join(valid)}"
    if err["type"] == "missing":
        return f"{key}: required key is missing"
    if err["type"] == "finite_number":
        return f"{key}: must be a finite number"
    msg = str(err["msg"]).replace("Input should be", "must be").replace("Value error, ", "")
    return f"{key}: {msg}" if err["loc"] else msg


def describe_entry(e: Motor | Reducer) -> str:
    """``id (maker series)`` with ``[illustrative]`` when the entry cites no datasheet."""
    extra = " ".join(x for x in (e.spec.maker, e.spec.series) if x)
    tag = " [illustrative]" if e.illustrative else ""
    return f"{e.id}{f' ({extra})' if extra else ''}{tag}"



@dataclass(frozen=True)
class HoldingPair:
    """The lightest motor and reducer of a catalogue whose peak holds a joint torque."""

    motor: Motor
    reducer: Reducer
    joint_peak_nm: float  # motor peak x ratio x efficiency, N m

    @property
    def mass_kg(self) -> float:
        return (self.motor.spec.mass_kg or math.inf) + (self.reducer.spec.mass_kg or math.inf)


def lightest_holding_pair(catalog: Catalog, torque_nm: float) -> HoldingPair | None:
    """The lightest pair (motor + reducer mass; entries without a mass last) whose peak at the
    joint, ``motor peak x ratio x efficiency``, and whose reducer's repeated peak torque both
    reach ``torque_nm``; None when no pair does."""
    best: HoldingPair | None = None
    for r in catalog.reducers:
        if r.spec.repeated_peak_torque_nm < torque_nm:
            continue
        for m in catalog.motors:
            peak = m.spec.peak_torque_nm * r.spec.ratio * r.spec.efficiency
            if peak < torque_nm:
                continue
            pair = HoldingPair(m, r, peak)
            if best is None or (pair.mass_kg, peak, m.id, r.id) < (
                    best.mass_kg, best.joint_peak_nm, best.motor.id, best.reducer.id):
                best = pair
    return best
