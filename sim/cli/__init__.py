"""CLI layer: the ``cellsim`` command line (also ``python -m sim``).

Each sub-command lives in its own module of this package with ``register(sub)`` (adds its
parser) and sets ``func(args) -> int``. User mistakes (every :class:`CellsimError` but
:class:`InternalError`, planners' errors included) are printed as one line and exit with code
2; an :class:`InternalError`, or any other exception (a fault inside cellsim: its readers
turn every input mistake into a :class:`CellsimError`), prints its traceback and exits with 3,
never 1 (the code of a ``--strict`` run whose verdict fails).
May import every layer below.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys
import traceback
import warnings
from collections.abc import Sequence
from typing import Any

from sim import __version__
from sim.core.text import printable
from sim.errors import CellsimError, CellsimWarning, InternalError

#: Sub-command modules, in the order ``--help`` lists them.
COMMANDS = ("list", "plan", "ik", "workspace", "check", "run", "size", "render", "view",
            "export")


class Parser(argparse.ArgumentParser):
    """``argparse`` with cellsim's way of refusing input: a mistake on the command line (an
    unknown option, a missing or malformed value) is one line naming the command and the
    option, and exit 2, as every other input mistake (argparse's own usage block before it
    buried the line that says what is wrong); a value that starts with a minus and a digit
    (``--payload -1,2``) is a value, not an unknown option (as Python 3.13's argparse reads
    it), so that the option's own check says what is wrong with it. Sub-command parsers are of
    this class too."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"-\.?\d")

    def error(self, message: str) -> Any:  # argparse's signature: NoReturn
        self.exit(2, printable(f"{self.prog}: error: {message} (see {self.prog} --help)")
                  + "\n")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="cellsim",
        description="Physics simulation of industrial robot welding and pick cells on MuJoCo.",
    )
    parser.add_argument("--version", action="version", version=f"cellsim {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"sim.cli.{name}").register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    with warnings.catch_warnings():
        warnings.showwarning = _show_warning
        return _dispatch(args)


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: Any = None, line: str | None = None) -> None:
    """cellsim's own warnings as one line, ``cellsim: warning: ...``; others as Python
    prints them."""
    if issubclass(category, CellsimWarning):
        print(printable(f"cellsim: warning: {message}"), file=sys.stderr if file is None else file)
    else:
        _python_showwarning(message, category, filename, lineno, file, line)


_python_showwarning = warnings.showwarning


def _dispatch(args: argparse.Namespace) -> int:
    try:
        return int(args.func(args) or 0)
    except InternalError as exc:
        return _internal_fault(exc)
    except CellsimError as exc:
        print(printable(f"cellsim: error: {exc}{_holding_hint(exc)}"), file=sys.stderr)
        return 2
    except MemoryError:
        print("cellsim: error: out of memory (a size the input asks for is too large)",
              file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cellsim: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `cellsim plan ... | head`: stop quietly
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:
        message = io_error(exc)
        if message is None:
            return _internal_fault(exc)
        print(printable(f"cellsim: error: {message}"), file=sys.stderr)
        return 2
    except Exception as exc:  # noqa: BLE001  (the last line of defence: never exit 1)
        return _internal_fault(exc)


def _internal_fault(exc: BaseException) -> int:
    """A fault inside cellsim (an :class:`InternalError`, or any exception that is not a
    :class:`CellsimError`: cellsim's readers turn every input mistake into one of those):
    its traceback, one line saying so, exit 3."""
    traceback.print_exc()
    print(f"cellsim: internal error: {type(exc).__name__}: {exc} (a fault in cellsim, not in "
          "your input: please report it with the traceback above)", file=sys.stderr)
    return 3


def _holding_hint(exc: BaseException) -> str:
    """For drives that cannot hold the arm (a :class:`~sim.errors.HoldError`, also as the
    context of the error that reports it): the lightest pair of the starter catalogue that
    would pass that check on each such joint."""
    from sim.errors import HoldError

    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and not isinstance(e, HoldError) and id(e) not in seen:
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    if not isinstance(e, HoldError) or not e.needs:
        return ""
    from sim.analysis.catalog import (
        lightest_holding_pair,
        load_catalog,
        starter_catalog,
    )

    try:
        cat = load_catalog(starter_catalog())
    except CellsimError:
        return ""
    parts = []
    for joint, need in e.needs.items():
        pair = lightest_holding_pair(cat, need)
        parts.append(f"{joint}: none" if pair is None else
                     f"{joint}: {pair.motor.id} + {pair.reducer.id} ({pair.joint_peak_nm:.4g} N m "
                     f"at the joint, {pair.motor.spec.peak_torque_nm:g} N m peak x "
                     f"{pair.reducer.spec.ratio:g} x {pair.reducer.spec.efficiency:g})")
    return ("; the lightest pair of the starter catalogue that would hold it: "
            + "; ".join(parts))


#: Operating-system errors that are the place's, not cellsim's: reported as one line with the
#: path (the run folder's previous result is left as it was: runs write to a hidden sibling).
_IO_ERRNOS = ("ENOSPC", "EDQUOT", "EACCES", "EPERM", "EROFS", "ENAMETOOLONG", "ENOTDIR",
              "EISDIR", "EMFILE", "EFBIG", "EIO")


def io_error(exc: OSError) -> str | None:
    """One line for a disk or permission error (``None`` for other OS errors)."""
    import errno

    codes = {getattr(errno, name) for name in _IO_ERRNOS if hasattr(errno, name)}
    if exc.errno not in codes:
        return None
    where = exc.filename if exc.filename is not None else "(a file cellsim was writing)"
    return f"{where}: {exc.strerror or exc}"


if __name__ == "__main__":
    sys.exit(main())
