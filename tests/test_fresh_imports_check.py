"""An import never hands over a bundle that fails its own check (issue 25): fresh
imports of tools/make_levels.py's levels, made with import-arena alone, pass `check`
with 0 errors (a corridor too narrow for the heavy tank included: the manifest's
[vehicles] too_big says play refuses it there, so check does not judge the spawns by it)."""

from __future__ import annotations

import pytest

from level_helpers import import_level
from tanktool.check.runner import run_check

LEVELS = ("ramps_and_decks", "rolling_terrain", "bridge", "two_storeys", "corridor", "narrow_deck")


@pytest.mark.parametrize("name", LEVELS)
def test_a_fresh_import_passes_check(tmp_path, name):
    bundle = import_level(tmp_path, name)
    report = run_check([bundle])
    errors = [d.format() for d in report.diagnostics if d.severity == "error"]
    assert not errors, errors
