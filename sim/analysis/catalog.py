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

Mistakes are reported as one line naming the file, the entry (``motors[3]`` and its id) and
the key, with the valid keys where a key is unknown.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from sim.core.resources import models_dir
from sim.errors import CatalogError


def starter_catalog() -> Path:
    """The shipped starter catalogue (``models/catalog/starter.toml``)."""
    return models_dir() / "catalog" / "starter.toml"


class _Entry(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=False, allow_inf_nan=False, frozen=True)


class MotorSpec(_Entry):
    """A servo motor (catalogue data, SI units)."""

    id: str = Field(min_length=1)
    maker: str = ""
    series: str = ""
    rated_torque_nm: float = Field(gt=0)
    peak_torque_nm: float = Field(gt=0)
    rated_speed_rpm: float | None = Field(None, gt=0)
    max_speed_rpm: float = Field(gt=0)
    rotor_inertia_kg_m2: float = Field(gt=0)
    mass_kg: float | None = Field(None, gt=0)
    thermal_time_constant_s: float | None = Field(None, gt=0)
    torque_speed: list[tuple[float, float]] | None = None
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
            if len(pts) < 2 or any(b[0] <= a[0] for a, b in zip(pts, pts[1:])):
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
    ratio: float = Field(gt=1)
    rated_torque_nm: float = Field(gt=0)
    rated_input_speed_rpm: float = Field(gt=0)
    rated_life_h: float = Field(gt=0)
    repeated_peak_torque_nm: float = Field(gt=0)
    momentary_peak_torque_nm: float = Field(gt=0)
    efficiency: float = Field(gt=0, le=1)
    efficiency_note: str = ""
    input_inertia_kg_m2: float = Field(ge=0)
    max_input_speed_rpm: float = Field(gt=0)
    mass_kg: float | None = Field(None, gt=0)
    average_torque_limit_nm: float | None = Field(None, gt=0)
    max_average_input_speed_rpm: float | None = Field(None, gt=0)
    life_exponent: float = Field(3.0, ge=1, le=10)
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
    seen: dict[str, str] = {}
    for cat in catalogs:
        for e in (*cat.motors, *cat.reducers):
            if e.id in seen and seen[e.id] != cat.sources[0]:
                raise CatalogError(f"{cat.sources[0]}: id {e.id!r} is also in {seen[e.id]}")
            seen[e.id] = cat.sources[0]
    return Catalog(tuple(m for c in catalogs for m in c.motors),
                   tuple(r for c in catalogs for r in c.reducers),
                   tuple(s for c in catalogs for s in c.sources))


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
    key = ".".join(str(p) for p in err["loc"]) or "(entry)"
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
