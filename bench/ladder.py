"""The difficulty ladder: a round robin of one-on-one duels between the computer
agents (easy, normal, hard) and yardstick opponents written from issue 19
(``sim.agents.robots``: a BZFlag-style robot, a camper, a duellist, a novice) and the scripted
baseline (``sim.driver.ScriptedDriver``), on every bundled arena, under the game's
rules (``sim.rules.DEFAULT``).

Every pair plays ``--duels`` duels of ``--seconds`` (120) on each arena: duel k uses
seed k, and the first player of the pair is tank 0 when k is even and tank 1 when
it is odd, so neither gets the better spawn points.  A win is more kills; equal
kills is a draw.  Printed: win / loss / draw per pair and arena, then Elo ratings
over all duels (a Bradley-Terry fit, draws counting half, with one virtual draw per
pair so that a clean sweep stays finite; the players' mean is 1500) with 90 %
bootstrap intervals (duels resampled within each pair and arena), and the goals.

    python bench/ladder.py [--duels N] [--json] [--arenas a,b] (default: every bundled arena)
                           [--players scripted,robot,camper,duellist,novice,easy,normal,hard]
                           [--seconds S] [--vehicle light] [--boot B]
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import random
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.bots import BUILTIN, load_bot  # noqa: E402
from tanktool.content import bundled_names  # noqa: E402
from tanktool.sim.driver import ScriptedDriver  # noqa: E402
from tanktool.sim.match import load_match_arena, load_tank_spec  # noqa: E402
from tanktool.sim.world import World  # noqa: E402

PLAYERS = ("scripted", "robot", "camper", "duellist", "novice", "easy", "normal", "hard")
#: every bundled arena (box, fort, hills, maze, paper2002 at the time of writing)
ARENAS = tuple(bundled_names("arenas"))


def make_player(name: str, seed: int):
    """A driver for a player of the ladder (a built-in bot, or the scripted baseline)."""
    if name == "scripted":
        return ScriptedDriver(random.Random(seed))
    if name in BUILTIN:
        return load_bot(name).driver(seed)
    raise ValueError(f"unknown player {name!r} (one of {', '.join(PLAYERS)})")


def duel(arena, spec, a: str, b: str, seed: int, seconds: float) -> tuple[int, int]:
    """Kills of ``a`` and of ``b`` in one duel (``a`` is tank 0 on even seeds)."""
    first = seed % 2
    world = World(arena.walls, [spec, spec], arena.spawns, seed=seed, bounds=arena.bounds,
                  ground=arena.ground)
    drivers: list = [None, None]
    # the seeds are drawn in tank order, so a seed gives each side the same stream
    seeds = [world.rng.getrandbits(64) for _ in range(2)]
    drivers[first] = make_player(a, seeds[first])
    drivers[1 - first] = make_player(b, seeds[1 - first])
    tanks = world.tanks
    for _ in range(int(round(seconds / world.dt))):
        world.step(None, [d(world, t) for d, t in zip(drivers, tanks)])
    return tanks[first].kills, tanks[1 - first].kills


def fit_elo(players: list[str], games: list[tuple[int, int, float]], prior: float = 1.0) -> np.ndarray:
    """Elo ratings (mean 1500) from games (i, j, score of i in [0, 1]): the
    Bradley-Terry maximum likelihood with ties as half points (MM iterations),
    ``prior`` virtual draws per pair."""
    n = len(players)
    wins = np.zeros(n)
    count = np.zeros((n, n))
    for i, j, s in games:
        wins[i] += s
        wins[j] += 1.0 - s
        count[i, j] += 1.0
        count[j, i] += 1.0
    for i, j in itertools.combinations(range(n), 2):
        wins[i] += 0.5 * prior
        wins[j] += 0.5 * prior
        count[i, j] += prior
        count[j, i] += prior
    g = np.ones(n)
    for _ in range(2000):
        denom = (count / (g[:, None] + g[None, :])).sum(axis=1)
        new = wins / np.maximum(denom, 1e-300)
        new /= np.exp(np.mean(np.log(new)))
        if np.max(np.abs(np.log(new) - np.log(g))) < 1e-10:
            g = new
            break
        g = new
    r = 400.0 * np.log10(g)
    return r - r.mean() + 1500.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--duels", type=int, default=10, help="duels per pair and arena (default 10)")
    ap.add_argument("--seconds", type=float, default=120.0, help="simulated seconds per duel (default 120)")
    ap.add_argument("--arenas", default=",".join(ARENAS), help="comma-separated (default: every bundled arena)")
    ap.add_argument("--players", default=",".join(PLAYERS))
    ap.add_argument("--vehicle", default="light")
    ap.add_argument("--boot", type=int, default=300, help="bootstrap resamples for the Elo intervals")
    ap.add_argument("--first-seed", type=int, default=0, help="duel k uses seed first_seed + k")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    args = ap.parse_args(argv)
    players = [p for p in args.players.split(",") if p]
    for p in players:
        if p not in PLAYERS:
            ap.error(f"--players: {p!r} is not one of {', '.join(PLAYERS)}")
    if len(players) < 2 or args.duels < 1:
        ap.error("need at least two players and one duel")
    spec = load_tank_spec(args.vehicle)
    arenas = [load_match_arena(a) for a in args.arenas.split(",") if a]
    t0 = time.perf_counter()
    cells = []              # one per (arena, pair)
    games: list[tuple[int, int, float, int]] = []       # (i, j, score of i, cell)
    for arena in arenas:
        for a, b in itertools.combinations(players, 2):
            w = l = d = 0
            ka = kb = 0
            for k in range(args.duels):
                x, y = duel(arena, spec, a, b, args.first_seed + k, args.seconds)
                ka, kb = ka + x, kb + y
                s = 1.0 if x > y else 0.0 if x < y else 0.5
                w, l, d = w + (s == 1.0), l + (s == 0.0), d + (s == 0.5)
                games.append((players.index(a), players.index(b), s, len(cells)))
            cells.append({"arena": arena.name, "a": a, "b": b, "wins": w, "losses": l, "draws": d,
                          "kills": [ka, kb], "win_rate": w / args.duels})
            if not args.json:
                print(f"  {arena.name} {a}-{b}: {w}-{l}-{d} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
    elo = fit_elo(players, [(i, j, s) for i, j, s, _ in games])
    rng = np.random.default_rng(1)
    by_cell: dict[int, list[tuple[int, int, float]]] = {}
    for i, j, s, c in games:
        by_cell.setdefault(c, []).append((i, j, s))
    boots = []
    for _ in range(args.boot):
        sample = []
        for c, gs in by_cell.items():
            idx = rng.integers(0, len(gs), len(gs))
            sample.extend(gs[k] for k in idx)
        boots.append(fit_elo(players, sample))
    boots = np.array(boots) if boots else np.zeros((0, len(players)))
    ratings = []
    for k, p in enumerate(players):
        lo, hi = (np.percentile(boots[:, k], [5, 95]) if len(boots) else (elo[k], elo[k]))
        ratings.append({"player": p, "elo": round(float(elo[k]), 1), "lo": round(float(lo), 1),
                        "hi": round(float(hi), 1)})
    goals = _goals(cells, ratings, players, [a.name for a in arenas])
    out = {"vehicle": spec.name, "seconds_per_duel": args.seconds, "duels_per_cell": args.duels,
           "arenas": [a.name for a in arenas], "players": players, "rules": "sim.rules.DEFAULT",
           "cells": cells, "elo": ratings, "goals": goals, "wall_clock_s": round(time.perf_counter() - t0, 1)}
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"ladder: {spec.name} tanks, duels of {args.seconds:g} s, {args.duels} per pair and arena; "
          f"W-L-D of the first player of the pair")
    names = [a.name for a in arenas]
    head = f"{'pair':<18}" + "".join(f"{n:>16}" for n in names) + f"{'all':>16}"
    print(head)
    print("-" * len(head))
    for a, b in itertools.combinations(players, 2):
        row = f"{a + '-' + b:<18}"
        tw = tl = td = 0
        for n in names:
            c = next(c for c in cells if c["arena"] == n and c["a"] == a and c["b"] == b)
            tw, tl, td = tw + c["wins"], tl + c["losses"], td + c["draws"]
            row += f"{c['wins']:>5}-{c['losses']}-{c['draws']:<3} {100 * c['win_rate']:>3.0f}%"
        row += f"{tw:>5}-{tl}-{td:<3} {100 * tw / max(tw + tl + td, 1):>3.0f}%"
        print(row)
    print()
    print(f"{'player':<10} {'Elo':>6}  90 % interval")
    for r in sorted(ratings, key=lambda r: -r["elo"]):
        print(f"{r['player']:<10} {r['elo']:>6.0f}  [{r['lo']:.0f}, {r['hi']:.0f}]")
    print()
    for g in goals:
        print(f"{'met' if g['met'] else 'NOT MET':<8} {g['goal']}: {g['value']}")
    print(f"wall clock {out['wall_clock_s']:.0f} s")
    return 0


def _goals(cells: list[dict], ratings: list[dict], players: list[str], arenas: list[str]) -> list[dict]:
    """Issue 19's goals, each with the figures that decide it."""
    out = []

    def rate(a: str, b: str, arena: str) -> float | None:
        for c in cells:
            if c["arena"] == arena and {c["a"], c["b"]} == {a, b}:
                w = c["wins"] if c["a"] == a else c["losses"]
                return w / (c["wins"] + c["losses"] + c["draws"])
        return None

    for level, need in (("hard", 0.7), ("normal", 0.5)):
        for opp in ("robot", "camper"):
            if level in players and opp in players:
                rates = {n: rate(level, opp, n) for n in arenas}
                worst = min(v for v in rates.values() if v is not None)
                out.append({"goal": f"{level} wins >= {100 * need:.0f} % against {opp} on every arena",
                            "value": ", ".join(f"{n} {100 * v:.0f} %" for n, v in rates.items()),
                            "met": worst >= need})
    elo = {r["player"]: r["elo"] for r in ratings}
    for lo, hi in (("easy", "normal"), ("normal", "hard")):
        if lo in elo and hi in elo:
            out.append({"goal": f"{hi} >= 150 Elo above {lo}", "value": f"{elo[hi] - elo[lo]:+.0f}",
                        "met": elo[hi] - elo[lo] >= 150})
    if "novice" in players and "easy" in players:
        rates = {n: rate("novice", "easy", n) for n in arenas}
        out.append({"goal": "novice wins >= 40 % against easy on every arena",
                    "value": ", ".join(f"{n} {100 * v:.0f} %" for n, v in rates.items()),
                    "met": min(rates.values()) >= 0.4})
    return out


if __name__ == "__main__":
    raise SystemExit(main())
