"""A mistake on the command line is one line and exit 2, as every other input mistake.

argparse printed its usage block (4 to 9 lines) before the line that says what is wrong
(``cellsim render RUN --fps 0``, ``cellsim run ... --width -5``), and read ``--payload -1,2``
as an unknown option ("expected one argument") instead of a negative payload: both found by
new-user trials. Specification, over every sub-command and each of its options that takes a
value (read from the parser itself, so a new option is covered), on generated mistakes: an
unknown option, a value that is not of the option's kind, a missing value, a missing
argument; each gives exactly one line on stderr, ``cellsim <command>: error: ...`` naming the
option, nothing on stdout, exit 2 and no traceback. A value that starts with a minus and a
digit reaches the option's own check, which names the option and the value.
"""

from __future__ import annotations

import argparse
import contextlib
import io

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from sim.cli import COMMANDS, build_parser, main

PARSER = build_parser()
SUB = next(a for a in PARSER._actions if isinstance(a, argparse._SubParsersAction))
JUNK = "not-a-value!"


def _rejects_junk(action: argparse.Action) -> bool:
    try:
        action.type(JUNK)  # type: ignore[misc]
    except (ValueError, TypeError, argparse.ArgumentTypeError):
        return True
    return False


#: The options that take one value, per command, whose kind (``type``) rejects a word.
TYPED = sorted((cmd, a.option_strings[-1]) for cmd in COMMANDS
               for a in SUB.choices[cmd]._actions
               if a.option_strings and a.nargs is None and a.type is not None
               and _rejects_junk(a))
#: Every option that takes a value (one or more), per command.
VALUED = sorted((cmd, a.option_strings[-1]) for cmd in COMMANDS
                for a in SUB.choices[cmd]._actions
                if a.option_strings and a.nargs != 0 and not isinstance(a, argparse._HelpAction))


def _refused(argv: list[str]) -> str:
    out_buf, err_buf = io.StringIO(), io.StringIO()
    with pytest.raises(SystemExit) as exc, contextlib.redirect_stdout(out_buf), \
            contextlib.redirect_stderr(err_buf):
        code = main(argv)
        raise SystemExit(code)  # a command's own refusal returns 2 (not argparse's exit)
    out, err = out_buf.getvalue(), err_buf.getvalue()
    assert exc.value.code == 2, (argv, err)
    assert out == "" and "Traceback" not in err and "usage:" not in err, (argv, err)
    lines = err.splitlines()
    assert len(lines) == 1, (argv, err)
    return lines[0]


def test_the_parser_covers_options_of_every_kind():
    """The lists below are not empty: the specification reads the real parser."""
    assert len(TYPED) >= 15 and len(VALUED) > len(TYPED)
    assert {cmd for cmd, _ in VALUED} >= {"run", "size", "render", "ik", "export"}


@pytest.mark.parametrize("command, option", VALUED)
def test_an_option_without_its_value_is_one_line(command, option):
    line = _refused([command, "x", option])
    assert line.startswith(f"cellsim {command}: error: argument ") and option in line


@pytest.mark.parametrize("command, option", TYPED)
def test_a_value_of_the_wrong_kind_is_one_line_naming_the_option(command, option):
    line = _refused([command, "x", option, JUNK])
    assert line.startswith(f"cellsim {command}: error: argument ") and option in line
    assert line.endswith(f"(see cellsim {command} --help)")


@settings(max_examples=25, deadline=None)
@given(command=st.sampled_from(COMMANDS),
       name=st.from_regex(r"\A--[a-z][a-z-]{2,14}\Z"))
def test_an_unknown_option_is_one_line(command, name):
    known = {s for a in SUB.choices[command]._actions for s in a.option_strings}
    if name in known:
        return
    given_args = ["lrmate200ic5l", "400", "0", "300"] if command == "ik" else ["x"]
    given_args += [x for a in SUB.choices[command]._actions if a.required and a.option_strings
                   for x in (a.option_strings[-1], "x")]
    line = _refused([command, *given_args, name])
    assert line.startswith("cellsim") and name in line


@pytest.mark.parametrize("command", [c for c in COMMANDS if c != "list"])  # list: none
def test_a_missing_argument_is_one_line(command):
    line = _refused([command])
    assert line.startswith(f"cellsim {command}: error: the following arguments are required")


def test_no_command_and_an_unknown_command_are_one_line(capsys):
    assert "required: COMMAND" in _refused([])
    assert "invalid choice: 'bogus'" in _refused(["bogus"])


@settings(max_examples=10, deadline=None)
@given(values=st.lists(st.floats(-1e4, -1e-3), min_size=1, max_size=3))
@example(values=[-1.0, -1.0])  # a repeat: refused in one line, with no warning about it
def test_a_negative_value_reaches_the_options_own_check(values):
    """``--payload -1,2`` is a negative payload (refused by its check, naming the option
    and the value), not an unknown option ``-1,2``; a repeated bad value is refused before
    any warning about the repeat."""
    text = ",".join(f"{v:g}" for v in values)
    line = _refused(["size", "lrmate200ic_weld_plate", "--payload", text + ",2"])
    assert "--payload" in line and "expected one argument" not in line
    assert f"got {values[0]:g}" in line
