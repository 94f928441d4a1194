"""Free text in the user's files is plain text (issue 31: a cell description printed raw
terminal escape sequences).

Specification: a description or note holding a control character (Unicode category Cc, tab
and newline excepted) is refused when its file is read, one line naming the key; any other
text is kept as written; and nothing cellsim prints from a user's file or path sends a
control character to the terminal.
"""

from __future__ import annotations

import unicodedata

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.cell_files import CELL, make_cell
from support.scenarios import CAMPAIGN_BASE

from sim.cli import main


def _is_control(c: str) -> bool:
    """The oracle, from Unicode's own table: a control character, tab and newline allowed."""
    return unicodedata.category(c) == "Cc" and c not in "\t\n"


def _toml_string(text: str) -> str:
    """``text`` as a TOML basic string (every character escaped as \\uXXXX or \\UXXXXXXXX)."""
    return '"' + "".join(f"\\u{ord(c):04X}" if ord(c) < 0x10000 else f"\\U{ord(c):08X}"
                         for c in text) + '"'


TEXT = st.text(alphabet=st.characters(blacklist_categories=["Cs"]), max_size=12) | \
    st.sampled_from(["\x1b[31mred\x1b[0m", "back\bspace", "line\rover", "\x9b2J", "tab\there",
                     "two\nlines", "Ø40 mm cup — 5 kg"])


@pytest.fixture(scope="module")
def cell_root(tmp_path_factory):
    """One cell folder for every example (its mesh decomposed once, then cached)."""
    root = tmp_path_factory.mktemp("cell")
    make_cell(root)
    return root


@settings(max_examples=30, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=TEXT)
def test_a_cell_description_is_plain_text_or_refused(cell_root, capsys, text):
    scenario = cell_root / "user_weld.toml"
    cell = cell_root / "cells" / "user_cell.toml"
    cell.write_text(CELL.replace('description = "a user\'s cell',
                                 f"description = {_toml_string(text)}\nnote_unused = \"", 1)
                    .replace('\nnote_unused = "', "\n# ", 1))
    rc = main(["list", "--cell", str(cell)])
    out, err = capsys.readouterr()
    assert not any(_is_control(c) for c in out + err.replace("\n", ""))
    if any(_is_control(c) for c in text):
        assert rc == 2 and "user_cell.toml: description: " in err and "control character" in err
        assert len(err.strip().splitlines()) == 1
    else:
        assert rc == 0, err
        assert out.startswith(f"user_cell: {text}")
    assert scenario.is_file()


@pytest.mark.parametrize("key", ["description", "note"])
def test_a_scenario_s_free_text_is_plain(tmp_path, capsys, key):
    text = CAMPAIGN_BASE.replace('description = "base scenario of the hostile-input campaign"',
                                 'description = "base"\nnote = "ok \\u001b]0;title\\u0007"'
                                 if key == "note" else 'description = "\\u001b[2Jcleared"')
    (tmp_path / "s.toml").write_text(text)
    assert main(["check", str(tmp_path / "s.toml")]) == 2
    err = capsys.readouterr().err
    assert f"s.toml: {key}: " in err and "U+001B" in err and "\x1b" not in err


def test_a_path_with_an_escape_is_printed_escaped(tmp_path, capsys):
    """An error naming a file whose name holds ESC prints ``\\x1b``, not the byte."""
    bad = tmp_path / "evil\x1b[2J.toml"
    bad.write_text("name = \n")
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "\x1b" not in err and "evil\\x1b[2J.toml" in err
