"""A misspelt key in any table of a scenario's top level names the keys the table takes.

``[sizing] catalogue = "cat.toml"`` (for ``catalog``) was refused with "unknown key; valid
keys: " and an empty list, where the same typo in ``[simulation]`` lists the keys and
suggests the right one: the key lookup knew three of the four tables (found by a new-user
trial). Specification, for every table of the top level (read from the scenario's schema, so a
new table is covered) and generated misspellings of each of its keys (one letter dropped,
doubled or changed): one line naming ``<table>.<typo>``, with a list of valid keys that holds
the key it misspells.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.core.tomlschema import model_at
from sim.errors import ScenarioError
from sim.scenario import parse_scenario
from sim.scenario.schema import ScenarioSpec

BASE = (Path(__file__).resolve().parents[2] / "scenarios" / "lrmate200ic_weld_plate.toml"
        ).read_text()
#: (table, key) of every table of the top level and each key it takes.
KEYS = sorted((name, key) for name in ScenarioSpec.model_fields
              if (model := model_at(ScenarioSpec, (name,))) is not None and name != "robots"
              and name not in ("phases", "actions", "drives")
              for key in model.model_fields)


def test_the_tables_are_found():
    assert {t for t, _ in KEYS} >= {"simulation", "video", "sizing", "expect"}


@pytest.mark.parametrize("table, key", KEYS)
@settings(max_examples=3, deadline=None)
@given(data=st.data())
def test_a_misspelt_key_lists_the_tables_keys(table, key, data):
    i = data.draw(st.integers(0, len(key) - 1))
    how = data.draw(st.sampled_from(["drop", "double", "change"]))
    letter = data.draw(st.sampled_from("abcdefghijklmnopqrstuvwxyz"))
    typo = {"drop": key[:i] + key[i + 1:], "double": key[:i] + key[i] + key[i:],
            "change": key[:i] + letter + key[i + 1:]}[how]
    valid = set(model_at(ScenarioSpec, (table,)).model_fields)
    if typo in valid or not typo or not typo[0].isalpha():
        return
    head = f"[{table}]"
    text = BASE.replace(head, f"{head}\n{typo} = 1", 1) if head in BASE \
        else f"{BASE}\n{head}\n{typo} = 1\n"
    with pytest.raises(ScenarioError) as exc:
        parse_scenario(text, source="typo.toml")
    msg = str(exc.value)
    assert "\n" not in msg and f"{table}.{typo}: unknown key" in msg, msg
    listed = msg.split("valid keys: ", 1)[1].split(", ")
    assert key in listed, msg
