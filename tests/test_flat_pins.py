"""Flat arenas keep their behaviour (issue 25): matches recorded on the bundled flat
arenas before every arena got a ground play back bit for bit, and the 2002 arena's
walls and grid run numbers stay what they were (tools/record_flat_pins.py made them)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.replay import play_replay, read_replay

ROOT = Path(__file__).resolve().parent.parent
PINS = ROOT / "tests" / "data" / "flat_pins"
_spec = importlib.util.spec_from_file_location("record_flat_pins", ROOT / "tools" / "record_flat_pins.py")
pins = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pins)

CASES = [(a, b, s) for a in pins.ARENAS for b, s, _ in pins.MATCHES]


@pytest.mark.parametrize("arena,bot,seed", CASES, ids=[pins.pin_name(*c)[:-4] for c in CASES])
def test_flat_match_plays_back_bit_for_bit(arena: str, bot: str, seed: int) -> None:
    tape = read_replay(PINS / pins.pin_name(arena, bot, seed))
    playback = play_replay(tape, load_match_arena(arena), load_tank_spec(pins.VEHICLE))
    assert playback.matches, f"{arena} {bot} seed {seed}: final state {playback.digest} != {tape.header['final_state']}"
    # the pins are real matches: tanks drove, fired and (agents) scored
    tanks = playback.result.report["tanks"]
    assert sum(t["distance"] for t in tanks) > 50.0
    assert sum(t["shots"] for t in tanks) > 0


def test_paper2002_walls_and_runs_unchanged() -> None:
    pinned = np.load(PINS / "paper2002_grid.npz")
    now = pins.grid_numbers("paper2002")
    assert set(pinned.files) == set(now)
    for key in pinned.files:
        assert np.array_equal(pinned[key], now[key]), f"paper2002 {key} changed"
    # the numbers are the paper's: runs of valid nodes along rows and columns
    valid = pinned["valid"]
    assert valid.sum() > 1000
    assert (pinned["row_index"][valid] >= 1).all()
    assert (pinned["row_index"][valid] <= pinned["row_total"][valid]).all()
    assert (pinned["col_index"][valid] <= pinned["col_total"][valid]).all()
