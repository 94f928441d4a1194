"""The actuator selection from Python is the command line's (found by a new-user trial:
``sim.run`` and ``sim.evaluate`` ignored a scenario's ``[sizing] select = true``, and
``RunOptions(selection=True)`` was taken, then crashed with a traceback after the simulation).
Specification, on generated catalogues: ``sim.evaluate`` of a scenario whose ``[sizing]``
selects chooses, per joint, the motor and reducer ``cellsim run`` writes to
``selection.json``; ``RunOptions(selection=<catalogue path>)`` chooses the same from that
file, ``selection=False`` nothing; a selection of any other kind is one line naming
``RunOptions.selection`` before anything runs. The oracle is the command line's run folder;
a planted fault (the scenario's ``select`` not looked at) is caught."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import sim
from sim.cli import main
from sim.core.resources import scenarios_dir

BASE = "kacso_lrmate100ib_sequence1"


def _catalogue(motors: list[tuple[float, float]], ratios: list[int]) -> str:
    """A catalogue of made-up motors ``(rated torque N m, max speed rpm)`` and reducers of the
    given ratios (their torques scaled with the ratio)."""
    out = ['[catalog]\nname = "made up"\ndescription = "generated for a test"\n']
    for k, (rated, rpm) in enumerate(motors):
        out.append(f"""[[motors]]
id = "M{k}"
rated_torque_nm = {rated!r}
peak_torque_nm = {3.0 * rated!r}
max_speed_rpm = {rpm!r}
rotor_inertia_kg_m2 = {2e-5 * rated!r}
mass_kg = {0.5 + rated!r}
source = "generated"
""")
    for k, ratio in enumerate(ratios):
        out.append(f"""[[reducers]]
id = "R{k}"
ratio = {ratio}
rated_torque_nm = {0.4 * ratio!r}
rated_input_speed_rpm = 2000
rated_life_h = 7000
repeated_peak_torque_nm = {1.2 * ratio!r}
momentary_peak_torque_nm = {2.5 * ratio!r}
efficiency = 0.8
input_inertia_kg_m2 = 4e-6
max_input_speed_rpm = 6000
mass_kg = {0.005 * ratio!r}
source = "generated"
""")
    return "\n".join(out)


def _write(tmp: Path, catalogue: str, select: bool) -> Path:
    (tmp / "cat.toml").write_text(catalogue)
    scen = tmp / "sel.toml"
    text = (scenarios_dir() / f"{BASE}.toml").read_text()
    scen.write_text(text + f'\n[sizing]\nselect = {str(select).lower()}\ncatalog = "cat.toml"\n')
    return scen


def _chosen(result: Any) -> dict[str, tuple[str | None, str | None]]:
    return {j: (d.motor, d.reducer) for j, d in result.selection.items()}


def _cli_chosen(scen: Path, out: Path) -> dict[str, tuple[str | None, str | None]]:
    assert main(["run", str(scen), "--no-video", "--no-plots", "--out", str(out)]) in (0, 1)
    summary = json.loads((out / "summary.json").read_text())
    return {j: (d["motor"], d["reducer"]) for j, d in summary["selection"]["joints"].items()}


def _check(motors: list[tuple[float, float]], ratios: list[int]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        scen = _write(Path(tmp), _catalogue(motors, ratios), select=True)
        want = _cli_chosen(scen, Path(tmp) / "run")
        assert want  # the command line selected
        quiet = sim.RunOptions(video=False, plots=False, progress=False)
        assert _chosen(sim.evaluate(scen)) == want
        assert _chosen(sim.run(scen, quiet, out_dir=Path(tmp) / "api")) == want
        assert (Path(tmp) / "api" / "selection.json").is_file()
        assert _chosen(sim.evaluate(scen, sim.RunOptions(selection=False, video=False,
                                                         plots=False))) == {}
        plain = _write(Path(tmp), _catalogue(motors, ratios), select=False)
        assert _chosen(sim.evaluate(plain)) == {}
        by_path = sim.RunOptions(selection=Path(tmp) / "cat.toml", video=False, plots=False)
        assert _chosen(sim.evaluate(plain, by_path)) == want


motor = st.tuples(st.floats(0.05, 3.0), st.sampled_from([3000.0, 4500.0, 6000.0]))


@settings(max_examples=2, deadline=None, derandomize=True, database=None)
@given(motors=st.lists(motor, min_size=1, max_size=3),
       ratios=st.lists(st.sampled_from([30, 50, 80, 100, 120, 160]), min_size=1, max_size=3,
                       unique=True))
def test_python_selects_what_the_command_line_selects(motors: list[tuple[float, float]],
                                                      ratios: list[int]) -> None:
    _check(motors, ratios)


def test_the_planted_fault_of_ignoring_the_scenarios_select_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    import dataclasses

    import sim.api.runs as runs

    # as before the fix: a selection other than the loaded settings was never made
    monkeypatch.setattr(runs, "_selecting", lambda options, scenario: dataclasses.replace(
        options, selection=None))
    with pytest.raises(AssertionError):
        _check([(1.0, 6000.0)], [100])


@given(value=st.one_of(st.integers(), st.floats(), st.lists(st.integers(), max_size=2),
                       st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
                       st.binary(max_size=3), st.just("  ")))
def test_a_selection_of_another_kind_is_one_line(value: Any) -> None:
    with pytest.raises(sim.CellsimError) as err:
        sim.RunOptions(selection=value)
    assert str(err.value).startswith("RunOptions.selection: ") and "\n" not in str(err.value)
    assert err.value.key == "selection"
