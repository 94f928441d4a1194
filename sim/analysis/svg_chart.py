"""Line charts as SVG text, written directly: a grid of panels, each with its series (a line
with markers, solid or dashed), its own axes and ticks at round numbers, rows sharing their
y axis and columns their x axis, a legend under each top panel's title.

Why not matplotlib: a sweep's chart is drawn once per sweep, in the parent while (or after)
its workers simulate, and matplotlib's import, fonts and text layout cost 0.6 s of CPU, about
7 % of a 6-variant sweep on 2 cores (issue 29); this writer costs a few milliseconds. The
result is a vector image that browsers and Markdown viewers show as it is, at any zoom. The
run's own charts (torque, speed, tracking) stay matplotlib PNGs.
"""

from __future__ import annotations

import dataclasses
import html
import math
from collections.abc import Sequence

#: viridis at 0, 1/8, ..., 1 (matplotlib's table, every 32nd entry): colours of a series by
#: its position in an ordered list, linearly between these.
VIRIDIS = ((0x44, 0x01, 0x54), (0x47, 0x2d, 0x7b), (0x3b, 0x52, 0x8b), (0x2c, 0x72, 0x8e),
           (0x21, 0x91, 0x8c), (0x28, 0xae, 0x80), (0x5e, 0xc9, 0x62), (0xad, 0xdc, 0x30),
           (0xfd, 0xe7, 0x25))

#: Plot area of one panel and the space around it, px.
PANEL_W, PANEL_H = 400.0, 160.0
LEFT, RIGHT, GAP_X, GAP_Y, BOTTOM = 92.0, 16.0, 30.0, 34.0, 46.0
FONT = 11.0


@dataclasses.dataclass(frozen=True)
class Series:
    """One line: points ``(x[i], y[i])`` (a non-finite value breaks the line there), its colour
    (``#rrggbb``), dashed or solid, markers ``"circle"`` or ``"square"``, and its legend label
    (None: not in the legend)."""

    x: Sequence[float]
    y: Sequence[float]
    color: str
    dashed: bool = False
    marker: str = "circle"
    label: str | None = None


@dataclasses.dataclass(frozen=True)
class Panel:
    """One panel's series and texts (``ylabel`` lines are separated by ``\\n``)."""

    series: Sequence[Series]
    title: str | None = None
    xlabel: str | None = None
    ylabel: str | None = None
    legend: bool = False


def viridis(f: float) -> str:
    """The viridis colour at ``f`` in [0, 1], ``#rrggbb``."""
    f = min(max(float(f), 0.0), 1.0) * (len(VIRIDIS) - 1)
    i = min(int(f), len(VIRIDIS) - 2)
    t = f - i
    a, b = VIRIDIS[i], VIRIDIS[i + 1]
    return "#" + "".join(f"{round(u + (v - u) * t):02x}" for u, v in zip(a, b, strict=True))


def _nice(x: float, rounded: bool) -> float:
    """Heckbert's nice number near ``x`` > 0: 1, 2, 5 or 10 times a power of ten."""
    e = math.floor(math.log10(x))
    f = x / 10.0**e
    if rounded:
        n = 1.0 if f < 1.5 else 2.0 if f < 3.0 else 5.0 if f < 7.0 else 10.0
    else:
        n = 1.0 if f <= 1.0 else 2.0 if f <= 2.0 else 5.0 if f <= 5.0 else 10.0
    return n * 10.0**e


def nice_ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    """About ``n`` ticks at round numbers whose first is <= ``lo`` and last >= ``hi`` (the
    axis spans from the first to the last); a single value gets a span around it."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        lo, hi = 0.0, 1.0
    if hi < lo:
        lo, hi = hi, lo
    if hi - lo <= 1e-12 * max(abs(lo), abs(hi), 1e-300):
        pad = 0.1 * abs(lo) if abs(lo) > 1e-12 else 1.0
        lo, hi = lo - pad, hi + pad
    step = _nice(_nice(hi - lo, False) / max(n - 1, 1), True)
    a, b = math.floor(lo / step), math.ceil(hi / step)
    a -= a * step > lo  # a quotient rounded across a whole number
    b += b * step < hi
    return [k * step for k in range(a, b + 1)]


def tick_text(v: float, ticks: Sequence[float]) -> str:
    """A tick's label with as many decimals as the ticks' step needs; in scientific notation
    (``1.5e-8``) where a fixed-point label of these ticks would be longer than 7 characters
    (a motionless joint's torque of 1e-8 N m, a track's force of 1e6 N)."""
    step = abs(ticks[1] - ticks[0]) if len(ticks) > 1 else 1.0
    decimals = max(0, -math.floor(math.log10(step) + 1e-9))
    if max(len(f"{t:.{decimals}f}") for t in ticks) <= 7:
        text = f"{v:.{decimals}f}"
        return "0" if float(text) == 0.0 else text
    big = max(abs(t) for t in ticks)
    e = math.floor(math.log10(big) + 1e-9)
    digits = max(0, e - math.floor(math.log10(step) + 1e-9))
    mantissa = f"{v / 10.0**e:.{digits}f}"
    return "0" if float(mantissa) == 0.0 else f"{mantissa}e{e}"


def _finite(s: Series) -> list[tuple[float, float]]:
    return [(float(x), float(y)) for x, y in zip(s.x, s.y, strict=True)
            if math.isfinite(x) and math.isfinite(y)]


def axis(values: Sequence[float], margin: float = 0.05) -> tuple[float, float, list[float]]:
    """An axis for ``values``: its limits (their range widened by ``margin`` of it on each
    side, as matplotlib's, so no point sits on the frame) and its ticks at round numbers
    inside them (at least two: the limits move out to the ticks when fewer fall inside)."""
    v = [float(x) for x in values if math.isfinite(x)] or [0.0, 1.0]
    lo, hi = min(v), max(v)
    if hi - lo <= 1e-12 * max(abs(lo), abs(hi), 1e-300):
        pad = 0.1 * abs(lo) if abs(lo) > 1e-12 else 1.0
        lo, hi = lo - pad, hi + pad
    else:
        lo, hi = lo - margin * (hi - lo), hi + margin * (hi - lo)
    ticks = nice_ticks(lo, hi)
    inside = [t for t in ticks if lo - 1e-9 * (hi - lo) <= t <= hi + 1e-9 * (hi - lo)]
    if len(inside) < 2:
        return ticks[0], ticks[-1], ticks
    return lo, hi, inside


def _legend_rows(panel: Panel) -> list[list[tuple[str, Series]]]:
    """The legend's entries laid out in rows that fit the panel's width."""
    rows: list[list[tuple[str, Series]]] = [[]]
    width = 0.0
    for s in panel.series:
        if s.label is None:
            continue
        w = 30.0 + 0.6 * FONT * len(s.label) + 12.0
        if rows[-1] and width + w > PANEL_W:
            rows.append([])
            width = 0.0
        rows[-1].append((s.label, s))
        width += w
    return [r for r in rows if r]


def _marker(kind: str, x: float, y: float, color: str) -> str:
    if kind == "square":
        return (f'<rect x="{x - 3:.2f}" y="{y - 3:.2f}" width="6" height="6" fill="{color}"/>')
    return f'<circle cx="{x:.2f}" cy="{y:.2f}" r="3.2" fill="{color}"/>'


def grid_svg(panels: Sequence[Sequence[Panel]]) -> str:
    """SVG text of ``panels`` (rows of columns, every row as long): each row's panels share
    their y axis (the same ticks), each column's its x axis; x tick labels and the x label
    under the last row only, y tick labels and the y label left of the first column only.

    Each panel is a ``<g class="panel" data-row=".." data-col="..">`` holding its ticks
    (``<text class="xtick|ytick">``, at the tick's position: ``x`` for an x tick, ``y`` for a
    y tick) and one ``<polyline class="series" data-label="..">`` per unbroken run of a
    series' points, so a reader (or a test) can read the values back through the ticks; a
    legend entry is a ``<g class="legend" data-label="..">`` with its line in the series'
    colour.
    """
    n_rows, n_cols = len(panels), len(panels[0]) if panels else 0
    if n_rows == 0 or n_cols == 0 or any(len(r) != n_cols for r in panels):
        raise ValueError("grid_svg: panels must be a non-empty rectangle of rows and columns")
    legends = [_legend_rows(p) if p.legend else [] for p in panels[0]]
    has_title = any(p.title for p in panels[0])
    top = 12.0 + (18.0 if has_title else 0.0) + 16.0 * max(len(x) for x in legends) + 8.0
    width = LEFT + n_cols * PANEL_W + (n_cols - 1) * GAP_X + RIGHT
    height = top + n_rows * PANEL_H + (n_rows - 1) * GAP_Y + BOTTOM
    yaxes = [axis([y for p in row for s in p.series for _, y in _finite(s)]) for row in panels]
    xaxes = [axis([x for row in panels for s in row[c].series for x, _ in _finite(s)])
             for c in range(n_cols)]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
           f'viewBox="0 0 {width:.0f} {height:.0f}" font-family="DejaVu Sans, Arial, sans-serif" '
           f'font-size="{FONT:g}">',
           f'<rect width="{width:.0f}" height="{height:.0f}" fill="white"/>']
    esc = html.escape
    for r, row in enumerate(panels):
        for c, panel in enumerate(row):
            x0 = LEFT + c * (PANEL_W + GAP_X)
            y0 = top + r * (PANEL_H + GAP_Y)
            (xa, xb, xt), (ya, yb, yt) = xaxes[c], yaxes[r]

            def px(x: float, x0: float = x0, xa: float = xa, xb: float = xb) -> float:
                return x0 + (x - xa) / (xb - xa) * PANEL_W

            def py(y: float, y0: float = y0, ya: float = ya, yb: float = yb) -> float:
                return y0 + PANEL_H - (y - ya) / (yb - ya) * PANEL_H

            out.append(f'<g class="panel" data-row="{r}" data-col="{c}">')
            for v in yt:
                y = py(v)
                out.append(f'<line x1="{x0:.2f}" y1="{y:.2f}" x2="{x0 + PANEL_W:.2f}" '
                           f'y2="{y:.2f}" stroke="#000" stroke-opacity="0.12"/>')
                if c == 0:
                    out.append(f'<text class="ytick" x="{x0 - 5:.2f}" y="{y:.2f}" '
                               f'text-anchor="end" dominant-baseline="middle">'
                               f'{tick_text(v, yt)}</text>')
            for v in xt:
                x = px(v)
                out.append(f'<line x1="{x:.2f}" y1="{y0:.2f}" x2="{x:.2f}" '
                           f'y2="{y0 + PANEL_H:.2f}" stroke="#000" stroke-opacity="0.12"/>')
                if r == n_rows - 1:
                    out.append(f'<text class="xtick" x="{x:.2f}" y="{y0 + PANEL_H + 14:.2f}" '
                               f'text-anchor="middle">{tick_text(v, xt)}</text>')
            out.append(f'<rect x="{x0:.2f}" y="{y0:.2f}" width="{PANEL_W:g}" '
                       f'height="{PANEL_H:g}" fill="none" stroke="#000" stroke-width="0.8"/>')
            for s in panel.series:
                dash = ' stroke-dasharray="5,3"' if s.dashed else ""
                label = f' data-label="{esc(s.label)}"' if s.label is not None else ""
                run: list[tuple[float, float]] = []
                runs = [run]
                for x, y in zip(s.x, s.y, strict=True):
                    if math.isfinite(x) and math.isfinite(y):
                        run.append((px(float(x)), py(float(y))))
                    elif run:
                        run = []
                        runs.append(run)
                for pts in (p for p in runs if p):
                    coords = " ".join(f"{x:.2f},{y:.2f}" for x, y in pts)
                    out.append(f'<polyline class="series"{label} points="{coords}" fill="none" '
                               f'stroke="{s.color}" stroke-width="1.3"{dash}/>')
                    out.extend(_marker(s.marker, x, y, s.color) for x, y in pts)
            if r == 0:
                ty = 12.0 + (12.0 if has_title else 0.0)
                if panel.title:
                    out.append(f'<text x="{x0 + PANEL_W / 2:.2f}" y="{ty:.2f}" '
                               f'text-anchor="middle" font-size="{FONT + 1:g}">'
                               f'{esc(panel.title)}</text>')
                for k, entries in enumerate(legends[c]):
                    ly = ty + 18.0 + 16.0 * k
                    lx = x0
                    for text, s in entries:
                        dash = ' stroke-dasharray="5,3"' if s.dashed else ""
                        out.append(f'<g class="legend" data-label="{esc(text)}">'
                                   f'<line x1="{lx:.2f}" y1="{ly - 4:.2f}" x2="{lx + 24:.2f}" '
                                   f'y2="{ly - 4:.2f}" stroke="{s.color}" '
                                   f'stroke-width="1.3"{dash}/>'
                                   + _marker(s.marker, lx + 12, ly - 4, s.color)
                                   + f'<text x="{lx + 30:.2f}" y="{ly:.2f}">{esc(text)}</text>'
                                   "</g>")
                        lx += 30.0 + 0.6 * FONT * len(text) + 12.0
            if r == n_rows - 1 and panel.xlabel:
                out.append(f'<text x="{x0 + PANEL_W / 2:.2f}" y="{y0 + PANEL_H + 34:.2f}" '
                           f'text-anchor="middle">{esc(panel.xlabel)}</text>')
            if c == 0 and panel.ylabel:
                lines = panel.ylabel.split("\n")
                cx, cy = x0 - 74.0 + 13.0 * (2 - len(lines)) / 2, y0 + PANEL_H / 2
                spans = "".join(f'<tspan x="{cx:.2f}" dy="{0 if i == 0 else 13}">'
                                f"{esc(t)}</tspan>" for i, t in enumerate(lines))
                out.append(f'<text x="{cx:.2f}" y="{cy:.2f}" text-anchor="middle" '
                           f'transform="rotate(-90 {cx:.2f} {cy:.2f})">{spans}</text>')
            out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


__all__ = ["Panel", "Series", "VIRIDIS", "axis", "grid_svg", "nice_ticks", "tick_text",
           "viridis"]
