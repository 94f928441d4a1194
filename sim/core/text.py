"""Free text from the user's files (descriptions, notes, titles): plain text only.

A description is printed by ``cellsim list``, in reports and in the run's summary; a control
character in it (an ANSI escape sequence ``ESC [``, a backspace, a carriage return) would
rewrite the user's terminal or hide a line of a report. Such text is refused when the file is
read (:data:`PlainText`, a pydantic string type: the message names the key and the
character); what cellsim prints from elsewhere (file names in error messages) goes through
:func:`printable`, which shows any control character as its escape.
"""

from __future__ import annotations

import re
from typing import Annotated

from pydantic import AfterValidator

#: Control characters a free text may not hold: C0 except tab and newline, DEL, and C1
#: (U+0080..U+009F, which terminals take as escapes too).
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def check_plain(text: str) -> str:
    """``text`` when it holds no control character (tab and newline allowed).

    Raises:
        ValueError: Naming the first one and its position (pydantic reports it with the key).
    """
    m = _CONTROL.search(text)
    if m:
        raise ValueError(f"control character U+{ord(m.group()):04X} at position {m.start()}: "
                         "text here is plain (no terminal escape sequences)")
    return text


#: A pydantic string field holding plain text (:func:`check_plain`).
PlainText = Annotated[str, AfterValidator(check_plain)]


def printable(text: str) -> str:
    """``text`` with every control character but newline and tab shown as its escape
    (``\\x1b``), for printing something cellsim did not check (a file name)."""
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], text)


def mm_text(length_m: float) -> str:
    """A length in m as mm for a message: one decimal, or 4 significant digits from 1e9 mm up
    (a typed 1e308 mm is not printed as 300 digits)."""
    mm = 1e3 * float(length_m)
    return f"{mm:.1f}" if abs(mm) < 1e9 else f"{mm:.4g}"


__all__ = ["PlainText", "check_plain", "mm_text", "printable"]
