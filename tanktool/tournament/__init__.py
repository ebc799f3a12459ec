"""Tournaments of bots (issue 31): a round robin of duels between built-in and user
bots over arenas and vehicles, with W-L-D per pairing, Elo ratings with bootstrap
intervals, a chart and the replay of every match; on this process, the local cores
or a Ray cluster, with the same report whichever (docs/tournament.md).

    from tanktool.tournament import TournamentConfig, run_tournament
    t = run_tournament(TournamentConfig(bots=("hard", "examples/bots/sniper.py:Sniper"), matches=4))
    print(table(t.report))
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable

from .elo import elo_table, fit_elo
from .report import FORMAT, add_timing, make_report, table
from .runners import RUNNERS, default_workers, runner
from .schedule import MatchTask, Player, TournamentConfig, resolve_players, schedule


@dataclass
class Tournament:
    """A finished tournament: the ``report`` (JSON-ready) and the ``replays``
    (file name, bytes), in match order."""

    report: dict[str, Any]
    replays: list[tuple[str, bytes]] = field(default_factory=list)


def run_tournament(config: TournamentConfig, *, run: str = "pool", workers: int | None = None,
                   ray_address: str = "local", record: bool = True,
                   on_match: Callable[[dict[str, Any]], None] | None = None,
                   on_replay: Callable[[str, bytes], None] | None = None) -> Tournament:
    """Play ``config``'s round robin with runner ``run`` (``serial``, ``pool`` or
    ``ray``) on ``workers`` processes (default: the local cores); ``on_match`` is
    called with each result as it comes in.  With ``on_replay(name, data)`` each
    replay is handed over as its match finishes (and not kept: a long tournament's
    replays need not fit in memory); else they are in ``Tournament.replays``."""
    config.check()
    players = resolve_players(config.bots)
    tasks = schedule(config, players, record=record)
    go = runner(run)
    workers = workers or default_workers()
    start = time.perf_counter()
    results = []
    it = go(tasks, workers, ray_address) if run == "ray" else go(tasks, workers)
    for r in it:
        if on_replay is not None and "replay" in r:
            on_replay(tasks[r["index"]].replay_name(), r.pop("replay"))
            r["replay"] = b""            # recorded, handed over
        results.append(r)
        if on_match is not None:
            on_match(r)
    wall = time.perf_counter() - start
    results.sort(key=lambda r: r["index"])
    report = make_report(config, players, tasks, results)
    add_timing(report, results, run, 1 if run == "serial" else workers, wall)
    replays = [(t.replay_name(), r["replay"]) for t, r in zip(tasks, results) if "replay" in r]
    if replays:
        for m, (name, _) in zip(report["matches"], replays):
            m["replay"] = name
    return Tournament(report, [] if on_replay is not None else replays)


__all__ = ["FORMAT", "MatchTask", "Player", "RUNNERS", "Tournament", "TournamentConfig", "default_workers",
           "elo_table", "fit_elo", "make_report", "resolve_players", "run_tournament", "schedule", "table"]
