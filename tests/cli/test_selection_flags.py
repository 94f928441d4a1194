"""The actuator-selection flags over a scenario's ``[sizing]`` keys, and a sweep's selection
written down (found by a new-user trial):

* with ``[sizing] select = true`` in the scenario, ``--catalog``, ``--life-h``, ``--dwell-s``,
  ``--rank`` were ignored (``run`` and ``size``), a missing ``--catalog`` file too; the flags
  now win over the keys, as ``--help`` and docs/scenario-format.md say;
* a selection flag with no selection to apply it to is refused in one line (it did nothing);
* ``cellsim size --select`` printed each variant's choice and wrote it nowhere: it now writes
  ``selection.csv`` (one row per variant and joint) and ``selection.json`` and a section of
  ``sweep.md``; each variant's choice is the one ``cellsim run --select`` makes for that
  payload (the oracle: the run's own selection.json)."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import pytest

from sim.cli import main

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = (ROOT / "scenarios" / "kacso_lrmate100ib_sequence1.toml").read_text()
SIZING = '\n[sizing]\nselect = true\ncatalog = "cat_a.toml"\ndwell_s = 1.0\n'
QUIET = ["--no-video", "--no-plots"]


@pytest.fixture()
def folder(tmp_path: Path) -> Path:
    for name in ("cat_a.toml", "cat_b.toml"):
        shutil.copy(ROOT / "models" / "catalog" / "starter.toml", tmp_path / name)
    (tmp_path / "sel.toml").write_text(SCENARIO.replace('name = "', 'name = "sel_', 1) + SIZING)
    (tmp_path / "plain.toml").write_text(SCENARIO)
    return tmp_path


def test_the_flags_win_over_the_scenarios_sizing_keys(folder: Path) -> None:
    out = folder / "run"
    assert main(["run", str(folder / "sel.toml"), "--out", str(out), *QUIET,
                 "--catalog", str(folder / "cat_b.toml"), "--life-h", "5", "--dwell-s", "0",
                 "--rank", "inertia"]) in (0, 1)
    doc = json.loads((out / "selection.json").read_text())
    assert [Path(p).name for p in doc["catalog"]] == ["cat_b.toml"]
    assert (doc["life_h"], doc["dwell_s"], doc["rank"]) == (5.0, 0.0, "inertia")


def test_without_flags_the_scenarios_keys_hold(folder: Path) -> None:
    out = folder / "run"
    assert main(["run", str(folder / "sel.toml"), "--out", str(out), *QUIET]) in (0, 1)
    doc = json.loads((out / "selection.json").read_text())
    assert [Path(p).name for p in doc["catalog"]] == ["cat_a.toml"]
    assert (doc["life_h"], doc["dwell_s"], doc["rank"]) == (20000.0, 1.0, "mass")


@pytest.mark.parametrize("command", ["run", "size"])
def test_a_missing_catalog_flag_is_refused_over_the_scenarios(
        folder: Path, command: str, capsys: pytest.CaptureFixture[str]) -> None:
    extra = QUIET if command == "run" else ["--workers", "1"]
    rc = main([command, str(folder / "sel.toml"), "--out", str(folder / "o"), *extra,
               "--catalog", str(folder / "nonexistent.toml")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "nonexistent.toml" in err[0], err
    assert not (folder / "o").exists()


@pytest.mark.parametrize("flag", [["--catalog", "cat_b.toml"], ["--life-h", "5"],
                                  ["--dwell-s", "0"], ["--rank", "margin"],
                                  ["--inertia-ratio-max", "3"]])
def test_a_selection_flag_without_a_selection_is_refused(
        folder: Path, flag: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    rc = main(["run", str(folder / "plain.toml"), "--out", str(folder / "o"), *QUIET, *flag])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == [f"cellsim: error: {flag[0]}: for an actuator selection; give "
                               "--select too (or [sizing] select = true in the scenario)"], err
    assert not (folder / "o").exists()


def test_a_sweeps_selection_is_written_and_is_each_payloads_run_selection(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sweep = folder / "sweep"
    payloads = (0.0, 2.0)
    assert main(["size", str(folder / "plain.toml"), "--select", "--catalog",
                 str(folder / "cat_b.toml"), "--payload", ",".join(map(str, payloads)),
                 "--workers", "1", "--out", str(sweep), "--quiet"]) == 0
    assert "selection.csv, selection.json" in capsys.readouterr().out
    with (sweep / "selection.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    doc = json.loads((sweep / "selection.json").read_text())
    assert len(doc["variants"]) == len(payloads)
    md = (sweep / "sweep.md").read_text()
    assert "## Actuator selection" in md
    for p, variant in zip(payloads, doc["variants"], strict=True):
        run, one = folder / f"run_{p:g}", folder / f"one_{p:g}.toml"
        one.write_text(f"payload_kg = {p!r}\n" + SCENARIO)
        assert main(["run", str(one), "--out", str(run), *QUIET, "--select",
                     "--catalog", str(folder / "cat_b.toml")]) in (0, 1)
        want = json.loads((run / "selection.json").read_text())["joints"]
        assert variant["payload_kg"] == p
        got = variant["selection"]["joints"]
        assert {j: (v["motor"], v["reducer"]) for j, v in got.items()} == \
            {j: (v["motor"], v["reducer"]) for j, v in want.items()}
        mine = [r for r in rows if float(r["payload_kg"]) == p]
        assert [r["joint"] for r in mine] == list(want)
        for r in mine:
            w = want[r["joint"]]
            assert (r["motor"], r["reducer"]) == (w["motor"] or "", w["reducer"] or "")
            if w["motor"]:
                assert float(r["ratio"]) == w["ratio"]
                assert f"{w['motor']} + {w['reducer']}" in md
