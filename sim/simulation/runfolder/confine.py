"""Confinement of a run folder's ``model.xml``: every file the model makes MuJoCo (4.0) read
is resolved exactly as MuJoCo resolves it and must lie inside the run folder.

Owns MuJoCo's path rules (``FilePath``: absolute prefixes, lexical reduction, ``strippath``,
``meshdir``/``texturedir``/``assetdir``), the model's file attributes and the elements refused
(``<include>``, ``<model file>``, plugins, a DOCTYPE).
May import: :mod:`sim.core.files`, :mod:`sim.errors` and the run folder's schema.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from sim.core.files import check_input, read_input
from sim.errors import RunFolderError
from sim.simulation.runfolder.schema import (
    MAX_ASSET_BYTES,
    MAX_MODEL_BYTES,
    file_error,
    short_repr,
)

# --------------------------------------------------------------------- model.xml's files
#: MJCF elements whose file attributes MuJoCo resolves against ``<compiler meshdir>`` (height
#: fields, skins and flexcomp meshes too, not only meshes) or ``texturedir``, and the
#: attributes it reads files from.
_MESHDIR_FILES: dict[str, tuple[str, ...]] = {
    "mesh": ("file",), "hfield": ("file",), "skin": ("file",), "flexcomp": ("file",),
}
_TEXTUREDIR_FILES: dict[str, tuple[str, ...]] = {
    "texture": ("file", "fileright", "fileleft", "fileup", "filedown", "filefront",
                "fileback"),
}
#: Elements that read other files cellsim does not follow: refused in a run folder's model.
_REFUSED_ELEMENTS: dict[str, str] = {
    "include": "includes another file",
    "model": "attaches another model file (<model file=...>)",
    "plugin": "uses a MuJoCo plugin, which may read files cellsim cannot check",
    "extension": "uses a MuJoCo plugin (<extension>), which may read files cellsim cannot check",
}
#: Most elements of a run folder's ``model.xml`` (the shipped cells have a few thousand).
MAX_MODEL_ELEMENTS = 1_000_000


def _mj_abs_prefix(path: str) -> str:
    """The part of ``path`` MuJoCo takes for an absolute prefix (its ``FilePath::AbsPrefix``):
    a leading ``/`` or ``\\``, or everything up to a ``:/`` or ``:\\`` ("" when relative)."""
    if not path:
        return ""
    if path[0] in "/\\":
        return path[0]
    for mark in (":/", ":\\"):
        i = path.find(mark)
        if i >= 0:
            return path[:i + 2]
    return ""


def _mj_reduce(path: str) -> str:
    """``path`` as MuJoCo reduces it (``FilePath::PathReduce``): ``\\`` and ``/`` both separate,
    ``.`` and empty parts go, ``..`` removes the part before it (lexically, not as the file
    system would through a symbolic link), parts are joined with ``/``."""
    prefix = _mj_abs_prefix(path)
    parts: list[str] = []
    start = len(prefix)
    for i in range(start, len(path)):
        if path[i] in "/\\":
            part, start = path[start:i], i + 1
            if part == ".." and parts and parts[-1] != "..":
                parts.pop()
            elif part not in (".", ""):
                parts.append(part)
    parts.append(path[start:])
    return prefix + "/".join(parts)


def _mj_join(base: str, name: str) -> str:
    """``base`` and ``name`` joined and reduced as MuJoCo does (``name`` when it is absolute)."""
    if not _mj_abs_prefix(name) and base:
        name = base + name if base[-1] in "/\\" else f"{base}/{name}"
    return _mj_reduce(name)


def _mj_strip(name: str) -> str:
    """``name`` without its folders, as ``<compiler strippath="true">`` reads it."""
    return name[max(name.rfind("/"), name.rfind("\\")) + 1:]



def _model_elements(data: bytes, where: str) -> list[tuple[str, dict[str, str], int]]:
    """The elements of ``model.xml`` that bear on the files MuJoCo reads: ``(tag, attributes,
    depth)`` of the root, the ``<compiler>`` sections and every element with a ``file*``
    attribute or a tag of :data:`_REFUSED_ELEMENTS`, in document order.

    Parsed with expat without namespace processing (tags and attribute names as MuJoCo's
    tinyxml2 reads them), as UTF-8 whatever the XML declaration says (tinyxml2 reads UTF-8 only);
    a DOCTYPE (entities: tinyxml2 does not read them as expat does) is refused.
    """
    from xml.parsers import expat

    class _Refused(Exception):
        pass

    kept: list[tuple[str, dict[str, str], int]] = []
    depth = 0
    count = 0

    def start(tag: str, attrs: dict[str, str]) -> None:
        nonlocal depth, count
        count += 1
        if count > MAX_MODEL_ELEMENTS:
            raise _Refused(f"more than {MAX_MODEL_ELEMENTS:,} elements")
        if (depth == 0 or tag == "compiler" or tag in _REFUSED_ELEMENTS
                or any(k.startswith("file") for k in attrs)):
            kept.append((tag, attrs, depth))
        depth += 1

    def end(tag: str) -> None:
        nonlocal depth
        depth -= 1

    def doctype(*args: Any) -> None:
        raise _Refused("a DOCTYPE (entity declarations), which a run folder's model has none of")

    parser = expat.ParserCreate(encoding="UTF-8")
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = doctype
    try:
        parser.Parse(data, True)
    except expat.ExpatError as exc:
        raise RunFolderError(f"{where}: model.xml is not valid XML "
                             f"({expat.errors.messages.get(exc.code, exc)}, line {exc.lineno})"
                             ) from None
    except _Refused as exc:
        raise RunFolderError(f"{where}: model.xml has {exc}") from None
    return kept


def model_file_names(data: bytes, where: str) -> list[tuple[str, str, str, bool]]:
    """The files and asset folders an MJCF model makes MuJoCo read, named as MuJoCo names them.

    Args:
        data: The model's XML (UTF-8).
        where: How messages name the run.

    Returns:
        ``(what, value, name, is_dir)`` for the effective ``meshdir`` and ``texturedir`` (when
        set) and for every file attribute: ``what`` as messages say it (``"<hfield file>"``),
        the attribute's ``value``, and ``name``, the path MuJoCo opens relative to the model
        file's folder (absolute when MuJoCo takes it for absolute): ``value`` with
        ``strippath`` applied, joined to its dir, reduced as :func:`_mj_reduce` does.

    Raises:
        RunFolderError: Not XML (:func:`_model_elements`), a root other than ``<mujoco>``, an
            element of :data:`_REFUSED_ELEMENTS`, a file attribute of an element cellsim does
            not know, a name with white space or control characters, or a drive or resource
            name (``c:...``, ``scheme:...``).
    """
    elements = _model_elements(data, where)
    if not elements or elements[0][0] != "mujoco":
        root = elements[0][0] if elements else "?"
        raise RunFolderError(f"{where}: model.xml's root element is <{short_repr(root)[1:-1]}>, not "
                             "<mujoco> (a run folder holds a compiled MJCF model)")
    dirs = {"meshdir": "", "texturedir": ""}
    strip = False
    for tag, attrs, depth in elements:
        if tag != "compiler" or depth != 1:  # MuJoCo reads the root's <compiler> sections only
            continue
        if "assetdir" in attrs:  # first: meshdir and texturedir of the same section override it
            dirs["meshdir"] = dirs["texturedir"] = attrs["assetdir"]
        for key in ("meshdir", "texturedir"):
            if key in attrs:
                dirs[key] = attrs[key]
        if "strippath" in attrs:
            strip = attrs["strippath"] == "true"

    def check_name(what: str, value: str) -> None:
        if any(c.isspace() or not c.isprintable() for c in value):
            raise RunFolderError(f"{where}: model.xml's {what} {short_repr(value)} holds white space "
                                 "or control characters; a run folder's file names have none")
        head = value.split("/")[0].split("\\")[0]
        if ":" in head and head.split(":")[0][:1].isalpha():
            raise RunFolderError(f"{where}: model.xml's {what} {short_repr(value)} is a drive or "
                                 "resource name (MuJoCo reads it as absolute), not a file of "
                                 "the run folder")

    out: list[tuple[str, str, str, bool]] = []
    for key, value in dirs.items():
        if value:
            check_name(f"<compiler {key}>", value)
            out.append((f"<compiler {key}>", value, _mj_reduce(value), True))
    for tag, attrs, _ in elements:
        if tag in _REFUSED_ELEMENTS:
            raise RunFolderError(f"{where}: model.xml {_REFUSED_ELEMENTS[tag]} "
                                 f"({short_repr(attrs.get('file', attrs.get('plugin', tag)))}); "
                                 "a run folder's model is self-contained")
        known = _MESHDIR_FILES.get(tag, _TEXTUREDIR_FILES.get(tag, ()))
        folder = dirs["meshdir" if tag in _MESHDIR_FILES else "texturedir"]
        for key, value in attrs.items():
            if not key.startswith("file"):
                continue
            what = f"<{short_repr(tag)[1:-1]} {short_repr(key)[1:-1]}>"
            if key not in known:
                raise RunFolderError(f"{where}: model.xml's {what} names a file "
                                     f"({short_repr(value)}) that cellsim does not check; a run "
                                     "folder's model reads none")
            if not value:
                continue
            check_name(what, value)
            name = _mj_strip(value) if strip else value
            out.append((what, value, _mj_join(_mj_reduce(folder), _mj_reduce(name)), False))
    return out


def confine_model_files(model_path: Path, where: str) -> str:
    """Refuse a ``model.xml`` that would make MuJoCo read a file outside its run folder, and
    say how to load it.

    Every file the model names is resolved exactly as MuJoCo (4.0) resolves it: the
    ``<compiler>`` sections in order (``assetdir`` sets both ``meshdir`` and ``texturedir``,
    ``meshdir``/``texturedir`` of the same section override it, a later section overrides an
    earlier one, ``strippath`` drops a name's folders); ``meshdir`` for ``<mesh>``,
    ``<hfield>``, ``<skin>`` and ``<flexcomp>`` files, ``texturedir`` for ``<texture>``'s
    seven file attributes; an absolute name bypasses the dirs; ``\\`` separates like ``/``
    and ``..`` is reduced lexically (MuJoCo's ``FilePath``). The result is resolved through
    symbolic links and must lie inside the folder; what exists there must be a regular file
    (a FIFO would block MuJoCo). ``<include>``, ``<model file>``, plugins, a DOCTYPE, a root
    other than ``<mujoco>`` (a URDF), names MuJoCo would read relative to the working
    directory or through a resource provider (``x:/..``, ``scheme:...``) and names with
    white space or control characters (which expat and tinyxml2 read differently) are refused.

    Args:
        model_path: The run folder's ``model.xml``.
        where: How messages name the run.

    Returns:
        The path to give ``mujoco.MjModel.from_xml_path`` (absolute, the folder resolved:
        the one the files were resolved against).

    Raises:
        RunFolderError: The first file or element at fault, named, one line.
    """
    folder = Path(os.path.realpath(model_path.parent))
    load = folder / model_path.name
    if "\\" in str(load):  # MuJoCo would read the backslash as a separator
        raise RunFolderError(f"{where}: the folder's path holds a backslash, which MuJoCo reads "
                             "as a separator; move the run folder")
    real = Path(os.path.realpath(load))
    if folder not in real.parents:
        raise RunFolderError(f"{where}: model.xml is a symbolic link to {str(real)!r}, outside "
                             "the run folder")
    data = read_input(load, file_error(load, f"{where}: model.xml"), "model file",
                      MAX_MODEL_BYTES)
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RunFolderError(f"{where}: model.xml is not UTF-8 text ({exc.reason} at byte "
                             f"{exc.start})") from None
    base = f"{folder}/"  # MuJoCo's model file dir: from_xml_path(load)'s folder
    for what, value, name, is_dir in model_file_names(data, where):
        resolved = _mj_join(base, name)
        if not resolved.startswith("/"):  # "x:/..": absolute to MuJoCo, relative to the OS
            raise RunFolderError(f"{where}: model.xml's {what} {short_repr(value)} is read as "
                                 f"{short_repr(resolved)}, relative to the working directory, not "
                                 "the run folder")
        target = Path(os.path.realpath(resolved))
        if not (folder in target.parents or (is_dir and target == folder)):
            raise RunFolderError(f"{where}: model.xml's {what} {short_repr(value)} resolves to "
                                 f"{str(target)!r}, outside the run folder")
        if not is_dir and os.path.lexists(target):
            check_input(target, file_error(target, f"{where}: model.xml's {what} "
                                                    f"{short_repr(value)} ({str(target)!r})"),
                        "model asset", MAX_ASSET_BYTES)
    return str(load)
