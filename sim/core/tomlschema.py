"""One-line messages for TOML files validated with pydantic (cell and tool files), and the
one rule for the numbers of every data file cellsim reads.

The scenario loader has its own (its phases are a tagged union); this one walks any nest of
models, lists and optional fields to name the key's path and, for a misspelt key, the valid
keys of the table it is in.

**Numbers.** A number in a robot folder (``robot.toml`` and its URDF), a bare URDF, a motor
and reducer catalogue or a cell file is read by :meth:`Quantity.problem`, whatever the format
(pydantic models use :attr:`Quantity.type`; the URDF and the catalogue call it directly):

* its type is strict: TOML's ``true``/``false`` is not 1/0 and a string is not a number;
* it is finite (``nan``, ``inf`` and an integer beyond the range of a 64-bit float are
  refused);
* it lies in the quantity's physical range, inclusive (the constants below, :data:`MASS_KG`
  and the others: a mass of 1e-308 kg or a gear ratio of 1e308 is a typo, and would only make
  MuJoCo's compiler or the dynamics fail later with less helpful words).

The message names the file and the key (``drives[0].gear_ratio: must be between 0.01 and
10000 (a gear ratio), got 1e+308``). The ranges are listed in ``docs/robot-format.md``,
``docs/cell-format.md`` and :mod:`sim.analysis.catalog`;
``tests/campaigns/test_data_validation.py`` takes every numeric key of a valid file and checks
its reader against them.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
import types
import typing
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, TypeVar

from pydantic import BaseModel, ConfigDict, PlainValidator, ValidationError
from pydantic_core import PydanticCustomError

M = TypeVar("M", bound=BaseModel)


class Strict(BaseModel):
    """Base of the file schemas: unknown keys, wrong types, NaN and inf are refused."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


#: The largest magnitude of a 64-bit float: a TOML integer beyond it is no number cellsim takes.
_FLOAT_MAX = 1.7976931348623157e308


def number_problem(value: object) -> str:
    """Why ``value`` read from a file is not a finite number ("" when it is): a boolean, a
    string, a table or an array; NaN or infinity; an integer beyond the range of a float."""
    if isinstance(value, bool):
        return "must be a number, got a boolean (true and false are not numbers)"
    if isinstance(value, int):
        if abs(value) > _FLOAT_MAX:
            return (f"must be a finite number, got an integer of {len(str(abs(value)))} digits "
                    "(beyond the range of a number)")
        return ""
    if isinstance(value, float):
        return "" if math.isfinite(value) else \
            "must be a finite number (NaN and inf are not allowed)"
    return f"must be a number, got {_toml_type(value)}"


@dataclass(frozen=True)
class Quantity:
    """A physical quantity a data file gives as a number, with the range cellsim takes it in
    (module docstring).

    Attributes:
        what: The quantity in words, for messages (``"a mass"``).
        unit: Its unit as the key names it (``"kg"``; ``""`` for a pure number).
        lo, hi: The range, inclusive: a value outside is a typo or a unit mistake.
        lo_open: ``lo`` itself is outside (a reducer's ratio is above 1, not 1).
    """

    what: str
    unit: str
    lo: float
    hi: float
    lo_open: bool = False

    def problem(self, value: object) -> str:
        """Why ``value`` is not this quantity ("" when it is): :func:`number_problem`, then
        the range."""
        bad = number_problem(value)
        if bad:
            return bad
        v = float(value)  # type: ignore[arg-type]
        if (self.lo < v if self.lo_open else self.lo <= v) and v <= self.hi:
            return ""
        unit = f" {self.unit}" if self.unit else ""
        if self.lo_open:
            return (f"must be above {self.lo:g} and at most {self.hi:g}{unit} ({self.what}), "
                    f"got {v!r}")
        return f"must be between {self.lo:g} and {self.hi:g}{unit} ({self.what}), got {v!r}"

    def read(self, value: object, key: str, error: Callable[[str], BaseException]) -> float:
        """``value`` as a float, or ``error`` with one line: ``key: why``."""
        bad = self.problem(value)
        if bad:
            raise error(f"{key}: {bad}")
        return float(value)  # type: ignore[arg-type]

    def _validate(self, value: object) -> float:
        bad = self.problem(value)
        if bad:
            raise PydanticCustomError("quantity", "{reason}", {"reason": bad})
        return float(value)  # type: ignore[arg-type]

    @property
    def type(self) -> Any:
        """The annotation of a pydantic field holding this quantity (``Annotated[float, ...]``;
        :func:`quantity_at` finds the quantity again from a key's location)."""
        return Annotated[float, PlainValidator(self._validate, json_schema_input_type=float),
                         self]


@dataclass(frozen=True)
class Columns:
    """Marks a field holding rows of numbers whose columns are different quantities (a DH
    table); the reader checks each column with its :class:`Quantity` and :func:`quantity_at`
    finds them (the cells are :data:`Real` to pydantic)."""

    quantities: tuple[Quantity, ...]


def _real(value: object) -> float:
    bad = number_problem(value)
    if bad:
        raise PydanticCustomError("quantity", "{reason}", {"reason": bad})
    return float(value)  # type: ignore[arg-type]


#: A finite number of no particular range (its range is checked by the reader: :class:`Columns`).
Real = Annotated[float, PlainValidator(_real, json_schema_input_type=float)]

# The physical ranges, inclusive (module docstring). Wide enough for any robot cell (a 10 m
# link, a 100 t payload, a 1 mg part), narrow enough that the physics stays in float range.
#: Lengths along a robot (DH ``a``, ``d``, a family's ``dims_mm``, a link's centre of mass), mm.
LENGTH_MM = Quantity("a length along a robot", "mm", -1e4, 1e4)
#: The same in metres (a URDF's origins).
LENGTH_M = Quantity("a length along a robot", "m", -10.0, 10.0)
#: Fixed angles (DH ``alpha`` and offsets), deg: two turns either way.
ANGLE_DEG = Quantity("a fixed angle", "deg", -720.0, 720.0)
#: The same in radians (a URDF's ``rpy``).
ANGLE_RAD = Quantity("a fixed angle", "rad", -4 * math.pi, 4 * math.pi)
#: A joint's range limits and home position, deg: three turns either way.
JOINT_DEG = Quantity("a joint position", "deg", -1080.0, 1080.0)
#: The same in radians (a URDF's ``<limit lower upper>``).
JOINT_RAD = Quantity("a joint position", "rad", -6 * math.pi, 6 * math.pi)
#: Joint speed limits, deg/s.
JOINT_SPEED_DEG_S = Quantity("a joint speed", "deg/s", 1e-3, 1e5)
#: The same in rad/s (a URDF's ``<limit velocity>``).
JOINT_SPEED_RAD_S = Quantity("a joint speed", "rad/s", math.radians(1e-3), math.radians(1e5))
#: Joint acceleration limits, deg/s^2.
JOINT_ACCEL_DEG_S2 = Quantity("a joint acceleration", "deg/s^2", 1e-3, 1e7)
#: A body's mass (a link, a whole arm, a part), kg: 1 mg to 100 t.
MASS_KG = Quantity("a mass", "kg", 1e-6, 1e5)
#: A payload, kg (0: none).
PAYLOAD_KG = Quantity("a payload", "kg", 0.0, 1e5)
#: An entry of an inertia tensor, kg m^2 (products of inertia may be negative).
INERTIA_KG_M2 = Quantity("an inertia", "kg m^2", -1e5, 1e5)
#: The smallest principal moment of inertia of a body with a mass, kg m^2 (MuJoCo refuses a
#: moving body whose inertia is below 1e-15; a 1 g bead of 0.1 mm radius has 4e-12).
MIN_PRINCIPAL_INERTIA_KG_M2 = 1e-12
#: A rotor's or a reducer's input inertia, kg m^2 (0: none given).
ROTOR_INERTIA_KG_M2 = Quantity("a rotor inertia", "kg m^2", 0.0, 100.0)
#: A gear ratio (motor turns per joint turn; 1: a direct drive).
GEAR_RATIO = Quantity("a gear ratio", "", 1e-2, 1e4)
#: An efficiency: 1 % to 100 %.
EFFICIENCY = Quantity("an efficiency", "", 1e-2, 1.0)
#: A torque (motor or joint side), N m.
TORQUE_NM = Quantity("a torque", "N m", 1e-6, 1e6)
#: A motor or reducer-input speed, rpm.
SPEED_RPM = Quantity("a motor speed", "rpm", 1e-3, 1e6)
#: A reducer's rated life, h.
LIFE_H = Quantity("a rated life", "h", 1.0, 1e7)
#: A motor's thermal time constant, s.
TIME_CONSTANT_S = Quantity("a thermal time constant", "s", 1e-3, 1e6)
#: A video's frame rate, frames per second (a time-lapse is [video] speed, not a low rate).
FPS = Quantity("a video frame rate", "fps", 1.0, 1000.0)


def quantity_at(root: type[BaseModel], loc: tuple[Any, ...]) -> Quantity | None:
    """The :class:`Quantity` of the number at ``loc`` in a file validated by ``root`` (list
    indices and table keys walked through), or None where ``loc`` is no number with a range:
    for tests that take the keys from a valid file and their ranges from the reader."""
    ann: Any = root
    meta: list[Any] = []
    row: Columns | None = None  # inside a row of a Columns field: the next part is a column
    for depth, part in enumerate(loc):
        if row is not None:
            last = depth == len(loc) - 1
            ok = last and isinstance(part, int) and 0 <= part < len(row.quantities)
            return row.quantities[part] if ok else None
        ann, meta = _unwrap(ann, meta)
        if isinstance(ann, type) and issubclass(ann, BaseModel):
            field = ann.model_fields.get(str(part))
            if field is None:
                return None
            ann, meta = field.annotation, list(field.metadata)
            continue
        cols = next((m for m in meta if isinstance(m, Columns)), None)
        args = typing.get_args(ann)
        origin = typing.get_origin(ann)
        if cols is not None:  # this part is the row; the next one picks the column
            row = cols
            continue
        if origin is list and args:
            ann, meta = args[0], []
        elif origin is dict and len(args) == 2:
            ann, meta = args[1], []
        else:
            return None
    ann, meta = _unwrap(ann, meta)
    return next((m for m in meta if isinstance(m, Quantity)), None)


def _unwrap(ann: Any, meta: list[Any]) -> tuple[Any, list[Any]]:
    """``ann`` without ``Optional`` and ``Annotated`` (their metadata added to ``meta``)."""
    while True:
        if typing.get_origin(ann) is Annotated:
            meta = meta + list(ann.__metadata__)
            ann = typing.get_args(ann)[0]
            continue
        args = [a for a in typing.get_args(ann) if a is not type(None)]
        if typing.get_origin(ann) in (typing.Union, types.UnionType) and len(args) == 1:
            ann = args[0]
            continue
        return ann, meta


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out: list[type[BaseModel]] = []
    for arg in typing.get_args(annotation):
        out += _models_in(arg)
    return out


def model_at(root: type[BaseModel], loc: tuple[Any, ...]) -> type[BaseModel] | None:
    """The model class validating the table at ``loc`` (list indices skipped)."""
    model: type[BaseModel] | None = root
    for part in loc:
        if isinstance(part, int) or model is None:
            continue
        field = model.model_fields.get(str(part))
        if field is None:
            return None
        found = _models_in(field.annotation)
        model = found[0] if found else None
    return model


def format_loc(loc: tuple[Any, ...]) -> str:
    """``("seams", 0, "object")`` -> ``seams[0].object``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
            continue
        # a key that is not a plain name (a newline, a quote, ...) is shown quoted, so the
        # message stays one line
        text = str(part) if re.fullmatch(r"[A-Za-z0-9_-]+", str(part)) else repr(str(part))
        out += f".{text}" if out else text
    return out or "(top level)"


def _toml_type(value: Any) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return f"the string {value!r}"
    if isinstance(value, int) and abs(value) > _FLOAT_MAX:
        return f"an integer of {len(str(abs(value)))} digits"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


def describe(exc: ValidationError, root: type[BaseModel], *,
             locate: Callable[[tuple[Any, ...]], type[BaseModel] | None] | None = None,
             strip: Callable[[tuple[Any, ...]], tuple[Any, ...]] | None = None,
             union_hint: str | None = None) -> str:
    """One line for the first error: the key's dotted path and what is wrong with it.

    Args:
        exc: pydantic's error.
        root: The file's top-level model.
        locate: The model validating the table at a location (default :func:`model_at`);
            for the valid keys listed after an unknown one.
        strip: Drops pydantic's union tags from a location (default: none).
        union_hint: Message for an unknown tag of a tagged union (``kind: must be one of``).
    """
    strip = strip or (lambda loc: loc)
    locate = locate or (lambda loc: model_at(root, loc))
    errors = exc.errors(include_url=False)
    # a misspelt key also makes the right key "missing": report the unknown key first
    err = min(errors, key=lambda e: e["type"] != "extra_forbidden")
    loc = strip(tuple(err["loc"]))
    path = format_loc(loc)
    kind = err["type"]
    if kind == "extra_forbidden":
        parent = locate(loc[:-1])
        valid = sorted(parent.model_fields) if parent else []
        close = difflib.get_close_matches(str(loc[-1]), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{path}: unknown key{hint}; valid keys: {', '.join(valid)}"
    if kind == "missing":
        return f"{path}: required key is missing"
    if kind == "finite_number":
        return f"{path}: must be a finite number (NaN and inf are not allowed)"
    if kind == "quantity":
        return f"{path}: {err['msg']}"
    if kind in ("union_tag_invalid", "union_tag_not_found") and union_hint:
        return f"{path}.{union_hint}"
    if kind in ("float_type", "int_type", "string_type", "list_type", "bool_type", "model_type",
                "dict_type"):
        expected = {"float_type": "a number", "int_type": "an integer", "string_type": "a string",
                    "list_type": "an array", "bool_type": "true or false",
                    "model_type": "a table", "dict_type": "a table"}[kind]
        return f"{path}: must be {expected}, got {_toml_type(err.get('input'))}"
    msg = str(err["msg"]).replace("Input should be", "must be").replace(
        "List should have", "must have").replace("String should match pattern",
                                                 "must match the pattern")
    return f"{path}: {msg.removeprefix('Value error, ')}"


def load_toml(path: Path, root: type[M], error: type[Exception]) -> tuple[M, dict[str, Any]]:
    """Read and validate a TOML file; every problem is one ``error`` naming the file and key.

    Returns:
        The validated model and the raw table.
    """
    from sim.core.files import read_input_text

    text = read_input_text(path, error, "file")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: invalid TOML: {exc}") from None
    try:
        return root.model_validate(raw), raw
    except ValidationError as exc:
        raise error(f"{path}: {describe(exc, root)}") from None


__all__ = ["ANGLE_DEG", "ANGLE_RAD", "EFFICIENCY", "FPS", "GEAR_RATIO", "INERTIA_KG_M2",
    "JOINT_ACCEL_DEG_S2", "JOINT_DEG", "JOINT_RAD", "JOINT_SPEED_DEG_S", "JOINT_SPEED_RAD_S",
    "LENGTH_M", "LENGTH_MM", "LIFE_H", "MASS_KG", "MIN_PRINCIPAL_INERTIA_KG_M2", "PAYLOAD_KG",
    "ROTOR_INERTIA_KG_M2", "SPEED_RPM", "TIME_CONSTANT_S", "TORQUE_NM", "Columns", "Quantity",
    "Real", "Strict", "describe", "format_loc", "load_toml", "model_at", "number_problem",
    "quantity_at"]
