"""The external-axes example of the docs (docs/cell-format.md's positioner cell,
docs/scenario-format.md's downhand scenario) is what a new user copies first: it must run
clean, and what it reports must be what its own numbers say (a new user found the first
version of it driving the torch into the floor)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _block(doc: str, first_line: str) -> str:
    text = (ROOT / "docs" / doc).read_text()
    i = text.index(f"```toml\n{first_line}")
    return text[i + len("```toml\n"):text.index("```\n", i + 8)]


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    folder = tmp_path_factory.mktemp("docs_example")
    cell = _block("cell-format.md", 'name = "positioner_cell"')
    (folder / "positioner_cell.toml").write_text(cell)
    (folder / "pipe_downhand.toml").write_text(
        _block("scenario-format.md", 'name = "pipe_downhand"'))
    return folder, tomllib.loads(cell)


@pytest.mark.slow  # a check and a run of a positioner cell (the fast share's ten minutes)
def test_the_documented_downhand_example_checks_clean_and_passes(example):
    import sim
    from sim.pipeline.check import check_scenario

    folder, cell = example
    scenario = sim.load_scenario(folder / "pipe_downhand.toml")
    assert check_scenario(scenario).findings == []
    r = sim.evaluate(scenario)
    assert r.verdict == "pass", [(c.name, c.subject, c.value) for c in r.failed_checks]
    # what the positioner carries: the cell file's own cylinders, solid steel
    steel = sum(7850.0 * math.pi * (o["radius_mm"] * 1e-3) ** 2 * o["length_mm"] * 1e-3
                for o in cell["objects"] if o.get("on") == "positioner")
    assert r.mechanisms["positioner"].carried_kg == pytest.approx(steel, rel=1e-9)
    (weld,) = r.to_dict()["weld"]
    assert weld["carried_by"] == "positioner" and weld["normal_from_vertical_deg"] < 2.0
    assert weld["travel_speed_mm_s"] == pytest.approx(10.0, rel=0.01)
