"""A script gets the file, key and line of a mistake as fields, not only inside a message.

A trial's script had to parse strings: only ``UnknownNameError`` carried fields. Every
:class:`sim.CellsimError` now has ``file``, ``key`` and ``line`` (None where the message
names none). Checked on real mistakes planted in real inputs (the expected file, key and
line are the test's own: where it planted the fault) and on generated messages.
"""

from __future__ import annotations

import shutil
import string
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import DATA, ROOT

import sim
from sim.errors import ScenarioError


def test_a_scenario_value_names_its_file_and_key(tmp_path):
    text = (ROOT / "scenarios" / "lrmate200ic_weld_plate.toml").read_text()
    head, sep, rest = text.partition("speed_mm_s = 8.0")
    phase = head.count("[[phases]]") - 1  # the phase the planted value is in
    path = tmp_path / "mine.toml"
    path.write_text(head + "speed_mm_s = -8.0" + rest)
    with pytest.raises(ScenarioError) as e:
        sim.load_scenario(path)
    assert isinstance(e.value, sim.CellsimError)
    assert (e.value.file, e.value.key, e.value.line) == ("mine.toml",
                                                         f"phases[{phase}].speed_mm_s", None)


def test_a_program_mistake_names_its_line(tmp_path):
    text = (DATA / "weld1.ls").read_text()
    lines = text.splitlines(keepends=True)
    k = next(i for i, ln in enumerate(lines) if "L P[2] 100mm/sec FINE" in ln)
    lines[k] = lines[k].replace("FINE", "FINEE")
    (tmp_path / "weld1.ls").write_text("".join(lines))
    (tmp_path / "s.toml").write_text(
        'name = "tp"\ndescription = "a TP program"\nrobot = "lrmate200ic5l"\n'
        'cell = "weld_table"\ntool = "mig_torch"\nprogram = "weld1.ls"\n')
    with pytest.raises(sim.CellsimError) as e:
        sim.evaluate(tmp_path / "s.toml")
    assert e.value.line == k + 1 and e.value.file is not None
    assert e.value.file.endswith("weld1.ls") or e.value.file.endswith("s.toml"), str(e.value)


def test_a_robot_file_inside_a_scenario_is_the_file_named(tmp_path):
    """An error in the robot.toml a scenario names: the robot.toml, not the scenario."""
    shutil.copytree(ROOT / "models" / "kuka_kr6r900_2", tmp_path / "kr6")
    toml = tmp_path / "kr6" / "robot.toml"
    text = toml.read_text().replace('name = "kr6r900_2"', 'name = "my_kr6"', 1)
    toml.write_text(text.replace("peak_torque_nm = 4.5\n", "peak_torque_nm = 0.5\n", 1))
    (tmp_path / "s.toml").write_text(
        'name = "r"\ndescription = "own robot"\nrobot = "./kr6"\n[[phases]]\nname = "m"\n'
        'planner = "434"\ntime_s = [0.0, 1.0]\njoints_deg = [[0, -90, 90, 0, 0, 0], '
        '[0, -80, 80, 0, 0, 0]]\n')
    with pytest.raises(ScenarioError) as e:  # the scenario's robot key, the robot's file
        sim.load_scenario(tmp_path / "s.toml")
    assert e.value.file == str(toml) and e.value.key == "drives[0] (j1)", str(e.value)


def test_an_unknown_name_keeps_its_own_fields():
    with pytest.raises(sim.UnknownNameError) as e:
        sim.load_scenario("no_such_scenario_here")
    assert e.value.name == "no_such_scenario_here" and e.value.file is None


_SEG = st.text(string.ascii_lowercase, min_size=1, max_size=8)


@given(folders=st.lists(_SEG, max_size=3), stem=_SEG,
       suffix=st.sampled_from(["toml", "ls", "urdf", "csv"]),
       key=st.lists(st.tuples(_SEG, st.one_of(st.none(), st.integers(0, 99))), min_size=1,
                    max_size=3),
       line=st.one_of(st.none(), st.integers(1, 10**5)),
       detail=st.text(string.ascii_letters + " ,.'=()[]", min_size=1, max_size=40))
def test_file_key_and_line_read_back_from_any_message(folders, stem, suffix, key, line, detail):
    file = "/".join([*folders, f"{stem}.{suffix}"])
    dotted = ".".join(f"{k}[{i}]" if i is not None else k for k, i in key)
    where = f"line {line}: " if line is not None else ""
    e = ScenarioError(f"{file}: {dotted}: {where}{detail}")
    assert (e.file, e.key, e.line) == (file, dotted, line)
    bare = ScenarioError(detail)
    assert (bare.file, bare.key, bare.line) == (None, None, None) or ": " in detail
    given_ = ScenarioError("anything", file=Path(file).name, key="k", line=3)
    assert (given_.file, given_.key, given_.line) == (Path(file).name, "k", 3)
