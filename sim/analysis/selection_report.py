"""The "Actuator selection" section of a run's sizing report, in ``sizing.md`` and in
``report.html`` from the same rows.

``sizing.md`` had no such section: a run with ``--select`` named its pairs in ``report.html``
only, while the README sends a reader to "the report's" section (found by a new-user trial).
:func:`selection_markdown` gives it; :mod:`sim.analysis.report` draws the HTML from
:func:`selection_intro`, :func:`selection_table` and :func:`pair_tables`.
May import: the selection's types and the reports' number texts.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from sim.analysis.catalog import describe_entry
from sim.analysis.report_text import num_text, pct_text
from sim.analysis.selection import REPORT_TOP

#: Columns of the section's table, one row per joint.
SELECTION_HEAD = ("joint", "motor", "reducer", "ratio", "mass (kg)", "hardest check",
                  "runner-up", "pairs passing")
#: Columns of a joint's table of checks (its chosen pair, or its closest when none passes).
CHECK_HEAD = ("check", "value", "limit", "unit", "margin", "source", "severity")
#: Columns of a joint's ranking of the pairs that pass.
RANK_HEAD = ("rank", "motor", "reducer", "mass (kg)", "min margin")


def selection_intro(sel: Any) -> str:
    """What was checked: the catalogue, the duty cycle, the life target and the ranking."""
    o = sel.options
    return (f"Catalogue {o.catalog.name}: {len(o.catalog.motors)} motors x "
            f"{len(o.catalog.reducers)} reducers per joint; duty cycle {sel.cycle_s:.4g} s "
            f"cycle + {o.dwell_s:g} s dwell; reducer life target {o.life_h:g} h; ranked by "
            f"{o.rank}; each check on the worse of the inverse dynamics and the simulated "
            "torque.")


def illustrative(sel: Any) -> bool:
    """Whether any catalogue entry holds numbers not verified against its datasheet."""
    o = sel.options
    return any(e.illustrative for e in (*o.catalog.motors, *o.catalog.reducers))


def verdict_text(sel: Any) -> str:
    return ("Every joint has a pair that passes every check." if sel.all_served else
            "Some joint has no pair that passes: see below.")


def selection_table(sel: Any) -> list[tuple[str, ...]]:
    """One row per joint (:data:`SELECTION_HEAD`): the pair chosen, or NONE and why."""
    rows: list[tuple[str, ...]] = []
    for j in sel.joints:
        if j.chosen is None:
            rows.append((j.joint, "NONE", "", "", "", j.reason, "", f"0 / {j.n_pairs}"))
            continue
        c, h = j.chosen, j.chosen.hardest
        runner = (f"{j.runner_up.motor.id} + {j.runner_up.reducer.id}" if j.runner_up else "-")
        rows.append((j.joint, describe_entry(c.motor), describe_entry(c.reducer),
                     f"{c.reducer.spec.ratio:g}", num_text(c.mass_kg, 3),
                     f"{h.name} {pct_text(h.margin_pct)}", runner,
                     f"{len(j.passing)} / {j.n_pairs}"))
    return rows


def pair_tables(sel: Any) -> list[tuple[str, list[tuple[str, ...]], list[tuple[str, ...]]]]:
    """Per joint with a pair to show: its title (``j2: chosen M + R`` or ``closest (fails)``),
    that pair's checks (:data:`CHECK_HEAD`) and the ranking of the passing pairs
    (:data:`RANK_HEAD`, the first :data:`~sim.analysis.selection.REPORT_TOP`)."""
    out = []
    for j in sel.joints:
        pair = j.chosen or j.closest
        if pair is None:
            continue
        title = (f"{j.joint}: {'chosen' if j.chosen else 'closest (fails)'} {pair.motor.id} + "
                 f"{pair.reducer.id}")
        checks = [(c.name, num_text(c.value), num_text(c.limit), c.unit,
                   pct_text(c.margin_pct), c.source, c.severity) for c in pair.checks]
        ranking = [(str(i + 1), p.motor.id, p.reducer.id, num_text(p.mass_kg, 3),
                    pct_text(p.min_margin_pct)) for i, p in enumerate(j.passing[:REPORT_TOP])]
        out.append((title, checks, ranking))
    return out


def _md_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    def cell(x: str) -> str:
        return str(x).replace("|", "\\|").replace("\n", " ")

    return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head),
            *("| " + " | ".join(cell(x) for x in r) + " |" for r in rows)]


def selection_markdown(sel: Any) -> list[str]:
    """The section's lines for ``sizing.md``: what was checked, the pair per joint, then per
    joint the chosen (or closest) pair's checks and the ranking of those that pass."""
    out = ["## Actuator selection", "", selection_intro(sel), ""]
    if illustrative(sel):
        out += ["Entries marked [illustrative] hold numbers not verified against their "
                "datasheet: verify before ordering.", ""]
    out += [verdict_text(sel), "", *_md_table(SELECTION_HEAD, selection_table(sel)), ""]
    for title, checks, ranking in pair_tables(sel):
        out += [f"### {title}", "", *_md_table(CHECK_HEAD, checks), ""]
        if ranking:
            out += [*_md_table(RANK_HEAD, ranking), ""]
    return out


__all__ = ["CHECK_HEAD", "RANK_HEAD", "SELECTION_HEAD", "illustrative", "pair_tables",
           "selection_intro", "selection_markdown", "selection_table", "verdict_text"]
