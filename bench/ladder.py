"""The difficulty ladder: a round robin of one-on-one duels between the computer
agents (easy, normal, hard) and yardstick opponents written from issue 28
(``sim.agents.robots``: a BZFlag-style robot, a camper, a duellist, a novice) and the scripted
baseline (``sim.driver.ScriptedDriver``), on every bundled arena and a level generated
by tools/make_levels.py (imported as an arena bundle, cached in the temp folder),
under the game's rules (``sim.rules.DEFAULT``).

Every pair plays ``--duels`` duels of ``--seconds`` (120) on each arena: duel k uses
seed k, and the first player of the pair is tank 0 when k is even and tank 1 when
it is odd, so neither gets the better spawn points.  A win is more kills; equal
kills is a draw.  Printed: win / loss / draw per pair and arena, then Elo ratings
over all duels (a Bradley-Terry fit, draws counting half, with one virtual draw per
pair played so that a clean sweep stays finite; the players' mean is 1500) with 95 %
bootstrap intervals (duels resampled within each pair and arena), and the goals
(issue 28's, and issue 30's for the novice).  The round robin and the Elo fit are
``tanktool tournament``'s (tanktool/tournament/), run on ``--workers`` local processes.
``--pairs`` plays only the pairings named (the Elo fit over them alone, which needs
them to link every player): a long measurement of what matters, affordable.

    python bench/ladder.py [--duels N] [--json] [--arenas a,b] (default: every bundled arena)
                           [--generated LEVEL[:SEED]] (default bridge; 'none': no generated arena)
                           [--players scripted,robot,camper,duellist,novice,easy,normal,hard]
                           [--pairs A-B,C-D] (only those pairings, A first; default every pair of --players)
                           [--seconds S] [--vehicle light] [--boot B] [--workers N]
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import tempfile
import time
from pathlib import Path


ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.content import bundled_names  # noqa: E402
from tanktool.sim.match import load_match_arena, load_tank_spec  # noqa: E402
import numpy as np  # noqa: E402

from tanktool.tournament import (MatchTask, TournamentConfig, default_workers, make_report,  # noqa: E402
                                 resolve_players)
from tanktool.tournament.elo import fit_elo as tournament_elo  # noqa: E402
from tanktool.tournament.runners import runner  # noqa: E402

PLAYERS = ("scripted", "robot", "camper", "duellist", "novice", "easy", "normal", "hard")
#: every bundled arena (box, fort, hills, maze, paper2002 at the time of writing)
ARENAS = tuple(bundled_names("arenas"))
#: the generated level played besides them (tools/make_levels.py: two plateaus with
#: ramps and a bridge over the passage between them)
GENERATED = "bridge"


def generated_arena(spec: str) -> Path:
    """The arena bundle of a generated level ``NAME[:SEED]`` (tools/make_levels.py),
    imported and its grid built once into the temp folder (``gen-NAME-SEED``)."""
    name, _, seed = spec.partition(":")
    sys.path.insert(0, str(ROOT / "tools"))
    import make_levels

    from click.testing import CliRunner

    from tanktool.cli.main import cli

    if not hasattr(make_levels, name) or name.startswith("_"):
        raise ValueError(f"--generated: no level {name!r} in tools/make_levels.py")
    kw = {"seed": int(seed)} if seed else {}
    out = Path(tempfile.gettempdir()) / "tanktool-ladder" / f"gen-{name}-{seed or 'default'}"
    if (out / "navgrid.npz").exists():
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    src = make_levels.write_obj(make_levels.level(name, **kw), out.parent / f"gen-{name}-{seed or 'default'}.obj")
    for args in (["-q", "import-arena", str(src), "-o", str(out), "--force"], ["-q", "build-navgrid", str(out)]):
        r = CliRunner().invoke(cli, args)
        if r.exit_code != 0:
            raise ValueError(f"--generated {spec}: {' '.join(args[1:2])} failed: {r.output.strip()}")
    return out


def fit_elo(players: list[str], games: list[tuple[int, int, float]], prior: float = 1.0):
    """The tournament's Bradley-Terry Elo fit (``tanktool.tournament.elo``) by player names."""
    return tournament_elo(len(players), games, prior)


def _parse(argv: list[str] | None) -> tuple[argparse.Namespace, list[str], list[tuple[str, str]]]:
    """The options, the players and the pairings (first player first) to play."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--duels", type=int, default=10, help="duels per pair and arena (default 10)")
    ap.add_argument("--seconds", type=float, default=120.0, help="simulated seconds per duel (default 120)")
    ap.add_argument("--arenas", default=",".join(ARENAS), help="comma-separated (default: every bundled arena)")
    ap.add_argument("--generated", default=GENERATED,
                    help=f"a tools/make_levels.py level NAME[:SEED] played too (default {GENERATED}; none: only --arenas)")
    ap.add_argument("--players", default=",".join(PLAYERS))
    ap.add_argument("--pairs", default="", help="only these pairings, A-B,C-D (A plays first); overrides --players")
    ap.add_argument("--vehicle", default="light")
    ap.add_argument("--boot", type=int, default=300, help="bootstrap resamples for the Elo intervals")
    ap.add_argument("--first-seed", type=int, default=0, help="duel k uses seed first_seed + k")
    ap.add_argument("--workers", type=int, default=default_workers(), help="processes (default: the local cores)")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    args = ap.parse_args(argv)
    if args.pairs:
        pairs = []
        for text in (t for t in args.pairs.split(",") if t):
            a, sep, b = text.partition("-")
            if not sep or a == b:
                ap.error(f"--pairs: {text!r} is not two different players A-B")
            pairs.append((a, b))
        players = list(dict.fromkeys(p for pair in pairs for p in pair))
    else:
        players = [p for p in args.players.split(",") if p]
        pairs = list(itertools.combinations(players, 2))
    for p in players:
        if p not in PLAYERS:
            ap.error(f"--players/--pairs: {p!r} is not one of {', '.join(PLAYERS)}")
    if len(players) < 2 or args.duels < 1 or not pairs:
        ap.error("need at least two players and one duel")
    if len(set(pairs) | {(b, a) for a, b in pairs}) < 2 * len(pairs):
        ap.error("--pairs: a pairing named twice")
    if not _linked(players, pairs):
        ap.error("--pairs: the pairings must link every player (else no Elo scale joins them)")
    return args, players, pairs


def _linked(players: list[str], pairs: list[tuple[str, str]]) -> bool:
    """Whether the pairings join every player into one graph."""
    reached, todo = {players[0]}, [players[0]]
    while todo:
        p = todo.pop()
        for a, b in pairs:
            for x, y in ((a, b), (b, a)):
                if x == p and y not in reached:
                    reached.add(y)
                    todo.append(y)
    return reached == set(players)


def _tasks(config: TournamentConfig, pairs: list[tuple[str, str]]) -> tuple[list, list[MatchTask]]:
    """The players and one task per duel, as the tournament's round robin (seed
    first_seed + k, the first player tank 0 on even k) but over ``pairs`` only."""
    players = resolve_players(config.bots)
    index = {name: i for i, name in enumerate(config.bots)}
    tasks: list[MatchTask] = []
    for arena in config.arenas:
        for a, b in ((index[a], index[b]) for a, b in pairs):
            for k in range(config.matches):
                tasks.append(MatchTask(len(tasks), a, b, arena, config.vehicles[0], k, config.first_seed + k, k % 2,
                                       float(config.seconds), (players[a], players[b]), config.budget, False))
    return players, tasks


def main(argv: list[str] | None = None) -> int:
    args, players, pairs = _parse(argv)
    spec = load_tank_spec(args.vehicle)
    refs: list = [a for a in args.arenas.split(",") if a]
    if args.generated and args.generated != "none":
        try:
            refs.append(generated_arena(args.generated))
        except ValueError as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
    arenas = [load_match_arena(a) for a in refs]
    for a, ref in zip(arenas, refs):
        if isinstance(ref, Path):
            a.name = f"gen-{args.generated.replace(':', '-')}"
    t0 = time.perf_counter()
    # the duels are the tournament's (tanktool.tournament: its players, match tasks,
    # runners and report), over the pairings asked for; seeds and sides fixed as there
    config = TournamentConfig(bots=tuple(players), arenas=tuple(str(r) for r in refs), vehicles=(args.vehicle,),
                              matches=args.duels, seconds=args.seconds, first_seed=args.first_seed,
                              boot=0)
    config.check()
    resolved, tasks = _tasks(config, pairs)
    results = []
    for r in runner("serial" if args.workers == 1 else "pool")(tasks, max(args.workers, 1)):
        results.append(r)
        if not args.json and len(results) % max(args.duels, 1) == 0:
            print(f"  {len(results)} duels ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
    report = make_report(config, resolved, tasks, results)
    names = {a_info.name: a_info.name for a_info in arenas}
    for a_info, ref in zip(arenas, refs):
        if isinstance(ref, Path):
            names[load_match_arena(ref).name] = a_info.name
    cells = []              # one per (arena, pair)
    for p in report["pairings"]:
        rows = [m for m in report["matches"] if (m["a"], m["b"], m["arena"]) == (p["a"], p["b"], p["arena"])]
        n = len(rows)
        cells.append({"arena": names.get(p["arena"], p["arena"]), "a": p["a"], "b": p["b"], "wins": p["wins"],
                      "losses": p["losses"], "draws": p["draws"], "kills": p["kills"],
                      "scored": [sum(m["kills"][0] > 0 for m in rows), sum(m["kills"][1] > 0 for m in rows)],
                      "win_rate": p["wins"] / n, "draw_rate": p["draws"] / n})
    ratings = _elo(players, tasks, results, args.boot)
    goals = _goals(cells, ratings, players, [a.name for a in arenas])
    out = {"vehicle": spec.name, "seconds_per_duel": args.seconds, "duels_per_cell": args.duels,
           "arenas": [a.name for a in arenas], "players": players, "pairs": [f"{a}-{b}" for a, b in pairs],
           "rules": "sim.rules.DEFAULT", "cells": cells, "elo": ratings, "goals": goals,
           "wall_clock_s": round(time.perf_counter() - t0, 1)}
    if args.json:
        print(json.dumps(out))
        return 0
    _print_tables(out, pairs)
    return 0


def _elo(players: list[str], tasks: list[MatchTask], results: list[dict], boot: int) -> list[dict]:
    """Elo with 95 % bootstrap intervals (duels resampled within each pair and arena,
    a seeded generator): the Bradley-Terry fit with one virtual draw per pairing
    played (the tournament's fit puts one on every pair, the same when all play)."""
    score = {r["index"]: r["score"] for r in results}
    by_cell: dict[tuple, list[tuple[int, int, float]]] = {}
    for t in tasks:
        by_cell.setdefault(t.cell, []).append((t.a, t.b, score[t.index]))
    virtual = [(a, b, 0.5) for a, b in dict.fromkeys((t.a, t.b) for t in tasks)]
    games = [g for gs in by_cell.values() for g in gs]
    elo = tournament_elo(len(players), games + virtual, 0.0)
    rng = np.random.default_rng(1)
    boots = []
    for _ in range(max(boot, 0)):
        sample = []
        for c in sorted(by_cell):
            gs = by_cell[c]
            sample.extend(gs[k] for k in rng.integers(0, len(gs), len(gs)))
        boots.append(tournament_elo(len(players), sample + virtual, 0.0))
    rows = []
    for k, name in enumerate(players):
        lo, hi = np.percentile([b[k] for b in boots], [2.5, 97.5]) if boots else (elo[k], elo[k])
        rows.append({"player": name, "elo": round(float(elo[k]), 1), "lo": round(float(lo), 1),
                     "hi": round(float(hi), 1)})
    return rows


def _print_tables(out: dict, pairs: list[tuple[str, str]]) -> None:
    """W-L-D per pair and arena, the Elo table and the goals."""
    cells, ratings, goals = out["cells"], out["elo"], out["goals"]
    print(f"ladder: {out['vehicle']} tanks, duels of {out['seconds_per_duel']:g} s, {out['duels_per_cell']} per "
          f"pair and arena; W-L-D of the first player of the pair")
    names = out["arenas"]
    head = f"{'pair':<18}" + "".join(f"{n:>16}" for n in names) + f"{'all':>16}"
    print(head)
    print("-" * len(head))
    for a, b in pairs:
        row = f"{a + '-' + b:<18}"
        tw = tl = td = 0
        for n in names:
            c = next(c for c in cells if c["arena"] == n and c["a"] == a and c["b"] == b)
            tw, tl, td = tw + c["wins"], tl + c["losses"], td + c["draws"]
            row += f"{c['wins']:>5}-{c['losses']}-{c['draws']:<3} {100 * c['win_rate']:>3.0f}%"
        row += f"{tw:>5}-{tl}-{td:<3} {100 * tw / max(tw + tl + td, 1):>3.0f}%"
        print(row)
    print()
    print(f"{'player':<10} {'Elo':>6}  95 % interval")
    for r in sorted(ratings, key=lambda r: -r["elo"]):
        print(f"{r['player']:<10} {r['elo']:>6.0f}  [{r['lo']:.0f}, {r['hi']:.0f}]")
    print()
    for g in goals:
        print(f"{'met' if g['met'] else 'NOT MET':<8} {g['goal']}: {g['value']}")
    print(f"wall clock {out['wall_clock_s']:.0f} s")


def _goals(cells: list[dict], ratings: list[dict], players: list[str], arenas: list[str]) -> list[dict]:
    """Issue 28's goals (and issue 30's for the novice), each with the figures that
    decide it; on the point estimates."""
    out = []

    def cell(a: str, b: str, arena: str) -> tuple[dict, bool] | None:
        for c in cells:
            if c["arena"] == arena and {c["a"], c["b"]} == {a, b}:
                return c, c["a"] == a
        return None

    def rate(a: str, b: str, arena: str) -> float | None:
        found = cell(a, b, arena)
        if found is None:
            return None
        c, first = found
        return (c["wins"] if first else c["losses"]) / (c["wins"] + c["losses"] + c["draws"])

    def every_arena(goal: str, a: str, b: str, need: float, of=rate) -> None:
        if a in players and b in players:
            if any(cell(a, b, n) is None for n in arenas):
                return      # a pairing --pairs left out
            rates = {n: of(a, b, n) for n in arenas}
            out.append({"goal": goal, "value": ", ".join(f"{n} {100 * v:.0f} %" for n, v in rates.items()),
                        "met": min(rates.values()) >= need})

    for level, opp, need in (("hard", "robot", 0.7), ("hard", "camper", 0.7), ("hard", "duellist", 0.5),
                             ("normal", "robot", 0.5)):
        every_arena(f"{level} wins >= {100 * need:.0f} % against {opp} on every arena", level, opp, need)
    draws = [(c["draw_rate"], f"{c['arena']} {c['a']}-{c['b']}") for c in cells]
    if draws:
        worst = max(draws)
        out.append({"goal": "no cell with more than 1 in 6 duels drawn",
                    "value": f"{sum(d > 1 / 6 for d, _ in draws)} of {len(draws)} cells over; most: {worst[1]} "
                             f"{100 * worst[0]:.0f} %", "met": worst[0] <= 1 / 6})
    elo = {r["player"]: r["elo"] for r in ratings}
    for lo, hi in (("easy", "normal"), ("normal", "hard")):
        if lo in elo and hi in elo:
            out.append({"goal": f"{hi} >= 150 Elo above {lo}", "value": f"{elo[hi] - elo[lo]:+.0f}",
                        "met": elo[hi] - elo[lo] >= 150})

    def scored(a: str, b: str, arena: str) -> float:
        c, first = cell(a, b, arena)  # type: ignore[misc]
        return c["scored"][0 if first else 1] / (c["wins"] + c["losses"] + c["draws"])

    every_arena("novice wins >= 40 % against easy on every arena", "novice", "easy", 0.4)
    every_arena("novice scores a kill in >= 80 % of duels against easy on every arena", "novice", "easy", 0.8,
                of=scored)
    return out

if __name__ == "__main__":
    raise SystemExit(main())
