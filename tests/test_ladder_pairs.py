"""bench/ladder.py's --pairs: only the pairings named are played (the first player
first), the Elo fit joins them, and pairings that cannot make a ladder are refused
without a traceback."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _ladder():
    spec = importlib.util.spec_from_file_location("ladder", ROOT / "bench" / "ladder.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_only_the_pairs_named_are_played(capsys):
    assert _ladder().main(["--duels", "1", "--seconds", "3", "--arenas", "box", "--generated", "none",
                           "--pairs", "hard-robot,normal-hard", "--boot", "5", "--workers", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [(c["a"], c["b"]) for c in out["cells"]] == [("hard", "robot"), ("normal", "hard")]
    assert {r["player"] for r in out["elo"]} == {"hard", "robot", "normal"}
    assert abs(sum(r["elo"] for r in out["elo"]) / 3 - 1500.0) < 1e-6
    goals = {g["goal"] for g in out["goals"]}
    assert "hard wins >= 70 % against robot on every arena" in goals
    assert not any("camper" in g for g in goals)       # a pairing not played: no goal on it


@pytest.mark.parametrize("pairs, why", [("hard-hard", "two different players"), ("hard-robot,robot-hard", "twice"),
                                        ("hard-robot,easy-normal", "link every player"),
                                        ("hard-nobody", "not one of")])
def test_pairs_that_make_no_ladder_are_refused(capsys, pairs, why):
    with pytest.raises(SystemExit) as e:
        _ladder().main(["--duels", "1", "--arenas", "box", "--pairs", pairs])
    assert e.value.code == 2 and why in capsys.readouterr().err


def test_the_fit_with_a_virtual_draw_per_pairing_played_is_the_tournaments_when_all_play():
    lad = _ladder()
    from tanktool.tournament import elo_table
    from tanktool.tournament.schedule import MatchTask

    tasks, results, games = [], [], []
    for i, (a, b, s) in enumerate([(0, 1, 1.0), (0, 1, 0.5), (0, 2, 1.0), (1, 2, 0.0), (1, 2, 1.0)]):
        tasks.append(MatchTask(i, a, b, "box", "light", 0, 0, 0, 1.0, (None, None)))
        results.append({"index": i, "score": s})
        games.append((a, b, s, {(0, 1): 0, (0, 2): 1, (1, 2): 2}[(a, b)]))
    mine = lad._elo(["a", "b", "c"], tasks, results, boot=0)
    theirs = elo_table(["a", "b", "c"], games, boot=0)
    assert [r["elo"] for r in mine] == [r["elo"] for r in theirs]
