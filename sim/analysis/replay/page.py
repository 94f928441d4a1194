"""The replay's HTML: a section of ``report.html`` holding the 3D replay and its charts.

Self-contained and offline: three.js (with its OrbitControls) and uPlot are shipped in
``vendor/`` (from the npm registry, with their licences) and inlined: three.js through an
import map whose entries are ``data:`` URLs, uPlot as a classic script, the page's own
``app.js`` as an inline module. The run's data is one JSON ``<script>`` block
(:mod:`sim.analysis.replay.payload`).

May import: the standard library only (data comes in as a dict).
"""

from __future__ import annotations

import base64
import html
import json
from functools import cache
from importlib import resources
from typing import Any

#: Vendored files (name in vendor/ -> what it is), with the versions shipped.
VENDOR = {
    "three.module.min.js": "three.js 0.170.0 (MIT), build/three.module.min.js",
    "OrbitControls.js": "three.js 0.170.0 (MIT), examples/jsm/controls/OrbitControls.js",
    "uPlot.iife.min.js": "uPlot 1.6.32 (MIT), dist/uPlot.iife.min.js",
    "uPlot.min.css": "uPlot 1.6.32 (MIT), dist/uPlot.min.css",
}

#: Comments around the section, so that ``cellsim view`` can replace it.
BEGIN, END = "<!-- cellsim-replay:begin -->", "<!-- cellsim-replay:end -->"

_CSS = """
#cellsim-replay{border:1px solid #ccd;border-radius:6px;padding:8px;margin:1em 0}
#cellsim-replay canvas.replay-canvas{width:100%;height:480px;display:block;background:#eef1f5}
#cellsim-replay .replay-bar{display:flex;gap:8px;align-items:center;margin:6px 0;flex-wrap:wrap}
#cellsim-replay input.replay-slider{flex:1;min-width:200px}
#cellsim-replay .replay-time{font-family:monospace;min-width:18em}
#cellsim-replay .replay-cursor{position:absolute;top:0;bottom:0;width:0;
 border-left:2px solid #e01010;pointer-events:none}
#cellsim-replay .replay-chart{margin-top:6px}
#cellsim-replay .replay-legend{font-size:.85em;color:#555}
"""


@cache
def _vendor(name: str) -> str:
    return (resources.files("sim.analysis.replay") / "vendor" / name).read_text("utf-8")


@cache
def _app() -> str:
    return (resources.files("sim.analysis.replay") / "app.js").read_text("utf-8")


def _data_url(js: str) -> str:
    return "data:text/javascript;base64," + base64.b64encode(js.encode("utf-8")).decode("ascii")


def _script_safe(text: str) -> str:
    """Text that cannot close its ``<script>`` element early."""
    return text.replace("</", "<\\/")


def replay_section(payload: dict[str, Any]) -> str:
    """The HTML of the replay section (heading, canvas, controls, charts and scripts)."""
    imports = {"imports": {
        "three": _data_url(_vendor("three.module.min.js")),
        "three/addons/controls/OrbitControls.js": _data_url(_vendor("OrbitControls.js")),
    }}
    data = json.dumps(payload, separators=(",", ":"), allow_nan=False)
    return "\n".join([
        BEGIN, "<h2>Replay</h2>",
        f"<style>{_vendor('uPlot.min.css')}{_CSS}</style>",
        '<div id="cellsim-replay">',
        '<canvas class="replay-canvas"></canvas>',
        '<div class="replay-bar"><button class="replay-play" type="button">Play</button>',
        '<input class="replay-slider" type="range" aria-label="time">',
        '<span class="replay-time"></span>',
        '<label>speed <select class="replay-speed"><option>0.25</option><option>0.5</option>'
        '<option selected>1</option><option>2</option><option>5</option><option>10</option>'
        "</select></label>",
        '<label>view <select class="replay-view"></select></label></div>',
        '<p class="replay-legend">Drag to orbit, right-drag to pan, wheel to zoom. Green: tool '
        "path; gold: the bead (arc on) laid so far; red: bodies in collision (and red bands on "
        "the charts); magenta: closest clearance points near their time. Click a chart to "
        "move the replay to that time.</p>",
        '<div class="replay-charts"></div>',
        "</div>",
        f'<script type="importmap">{json.dumps(imports)}</script>',
        f"<script>{_script_safe(_vendor('uPlot.iife.min.js'))}</script>",
        f'<script type="application/json" id="cellsim-replay-data">{_script_safe(data)}'
        "</script>",
        f'<script type="module">{_script_safe(_app())}</script>', END,
    ])


def with_replay(report: str | None, section: str, title: str = "cellsim replay") -> str:
    """``report.html``'s text with ``section`` in place of its replay (or after its title when
    it has none); a page of its own when there is no report."""
    if report is None:
        return ('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
                f"<title>{html.escape(title)}</title></head><body style=\"font-family:"
                f'system-ui,sans-serif;max-width:1200px;margin:1em auto"><h1>{html.escape(title)}'
                f"</h1>\n{section}\n</body></html>\n")
    a, b = report.find(BEGIN), report.find(END)
    if 0 <= a < b:
        return report[:a] + section + report[b + len(END):]
    at = report.find("</h1>")
    at = at + len("</h1>") if at >= 0 else report.find("<body>") + len("<body>")
    return report[:at] + "\n" + section + report[at:]
