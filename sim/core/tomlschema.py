"""One-line messages for TOML files validated with pydantic (cell and tool files).

The scenario loader has its own (its phases are a tagged union); this one walks any nest of
models, lists and optional fields to name the key's path and, for a misspelt key, the valid
keys of the table it is in.
"""

from __future__ import annotations

import difflib
import re
import tomllib
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ConfigDict, ValidationError

M = TypeVar("M", bound=BaseModel)


class Strict(BaseModel):
    """Base of the file schemas: unknown keys, wrong types, NaN and inf are refused."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


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


__all__ = ["Strict", "describe", "format_loc", "load_toml", "model_at"]
