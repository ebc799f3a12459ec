"""Computer opponents, measured: duels against the baseline bot, wall bumps, time to
first sight, time stuck, and the agents' CPU per simulated step.

For every bundled arena and difficulty:

* **duels**: N one-against-one matches (``--seconds`` each, default 120) of our agent
  against the baseline, the scripted bot of ``sim.driver.ScriptedDriver`` (roam to
  random waypoints, feel for walls, back off when stuck, turn on and shoot at the
  nearest tank within 60 degrees and 120 m, 3 degree aim error).  Match k uses seed k;
  the agent is tank 0 in even matches and tank 1 in odd ones, so neither gets the
  better spawns.  A win is more kills than the baseline; equal kills is a draw.
* **bound** (normal only): the same duels for an agent that cheats: told where the
  enemy is, it drives an A* path at it whenever it is not attacking or evading.  No
  searcher can find the enemy sooner, so its win rate is about the most a duel of that
  length allows.  In the maze, 60 s duels held it to about 75 % (one duel in eight
  ended without a meeting), which is why the duels last 120 s.
* **bumps/min**: wall bumps (the world's count: a wall contact with an impulse after
  0.25 s without one) per simulated minute, in those duels, ours and the baseline's.
* **stuck**: the fraction of 0.25 s samples, alive, with speed < 0.3 m/s and turn rate
  < 0.1 rad/s while not attacking (the baseline: while it has no target in view).
* **first sight**: the agent alone with an enemy that never moves (M runs, seed k,
  random spawns): simulated seconds until the enemy is first seen, median over the
  runs, capped at ``--cap`` s (runs that never saw it count as the cap); the baseline
  in the same situation beside it.

Then the CPU cost: 8 tanks on each arena, all agents (normal) or all baseline bots,
``--cpu-steps`` steps; the time spent deciding per simulated step, for all 8 together.

Then **dodging** (the game's rules, ``sim.rules.DEFAULT``, without spawn protection):
on an open 400 m field a gunner that never misses its aim (it stands, turns onto the
exact intercept of the target's true position and velocity, and fires only when
the shot's predicted miss is under 0.5 m: every shot is on target when fired) shoots
at a tank that holds a distance D facing it, for ``--dodge-seconds`` at each D.  The
target either stands ("still"), strafes at full strength and flips side every 3-6 s
("strafing"), or strafes so and dodges the shells it sees with the agents' own
``dodge.Evasion`` (noticed 0.25 s after they come into view, the hard agent's
reaction: "dodging").  Printed: the share of on-target shots that missed, by D.

    python bench/bots.py [--matches N] [--sight-runs M] [--seconds S] [--arenas a,b (default: all bundled)]
                         [--levels easy,normal,hard] [--no-bound] [--dodge-seconds S]
                         [--distances 10,20,...] [--json]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import random
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from tanktool.content import bundled_names  # noqa: E402
from tanktool.formats.walls_txt import WallList, aux_rectangle  # noqa: E402
from tanktool.bots import BotDriver, Perceiver, Senses  # noqa: E402
from tanktool.sim.agents import DIFFICULTIES, Agent, make_agents  # noqa: E402
from tanktool.sim.agents import aim, dodge  # noqa: E402
from tanktool.sim.agents.driving import trim  # noqa: E402
from tanktool.sim.commands import IDLE, Command  # noqa: E402
from tanktool.sim.driver import ScriptedDriver  # noqa: E402
from tanktool.sim.match import load_match_arena, load_tank_spec  # noqa: E402
from tanktool.sim.rules import DEFAULT as DEFAULT_RULES  # noqa: E402
from tanktool.sim.world import World  # noqa: E402

SAMPLE = 0.25   # seconds between stuck samples


def _stuck(tank) -> bool:
    return tank.alive and tank.speed() < 0.3 and abs(tank.omega) < 0.1


class Omniscient(Agent):
    """The bound: our agent, told where the enemy truly is (it cheats: radar).  Unless
    it is attacking or evading, it drives an A* path to the enemy, planned again every
    second."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.senses = dataclasses.replace(self.senses, radar=True)
        self.hunt: list[tuple[float, float]] = []
        self.hunt_at = -math.inf

    def think(self, view):
        cmd = super().think(view)
        if not view.radar or self.state in ("attack", "evade"):
            return cmd
        me, enemy = view.me, view.radar[0]
        if view.t >= self.hunt_at + 1.0:
            self.hunt_at = view.t
            self.hunt = view.map.path((me.x, me.z, me.y), (enemy.x, enemy.z, enemy.y), self.nav.grid)
        trim(self.hunt, me.x, me.z)
        if not self.hunt:
            return cmd
        return self.unstick(view, self.follow(view, self.hunt, speed=1.0, lookahead=4.0, corner=self.hunt[0]))


def duel(arena, spec, seed: int, level: str, seconds: float, agent=Agent) -> dict:
    """One agent against one baseline bot; the agent's and the baseline's numbers."""
    ours = seed % 2
    world = World(arena.walls, [spec, spec], arena.spawns, seed=seed, bounds=arena.bounds)
    drivers: list = [None, None]
    drivers[ours] = BotDriver(agent(level), world.rng.getrandbits(64))
    drivers[1 - ours] = ScriptedDriver(random.Random(world.rng.getrandbits(64)))
    agent, base = drivers[ours].bot, drivers[1 - ours]
    every = int(round(SAMPLE / world.dt))
    samples = [0, 0]
    stuck = [0, 0]
    tanks = world.tanks
    for k in range(int(round(seconds / world.dt))):
        world.step(None, [d(world, t) for d, t in zip(drivers, tanks)])
        if k % every == 0:
            a, b = tanks[ours], tanks[1 - ours]
            if a.alive:
                samples[0] += 1
                stuck[0] += _stuck(a) and agent.state != "attack"
            if b.alive:
                samples[1] += 1
                stuck[1] += _stuck(b) and base._target(world, b) is None
    a, b = tanks[ours], tanks[1 - ours]
    return {"kills": (a.kills, b.kills), "bumps": (a.wall_bumps, b.wall_bumps),
            "stuck": (stuck[0] / max(samples[0], 1), stuck[1] / max(samples[1], 1))}


def first_sight(arena, spec, seed: int, level: str | None, cap: float) -> float:
    """Seconds until the driver first sees a stationary enemy (``level`` None: the baseline)."""
    world = World(arena.walls, [spec, spec], arena.spawns, seed=seed, bounds=arena.bounds)
    rng = random.Random(world.rng.getrandbits(64))
    me, enemy = world.tanks
    if level is None:
        driver = ScriptedDriver(rng)

        def seen() -> bool:
            return driver._target(world, me) is enemy
    else:
        driver = BotDriver(Agent(level), rng.getrandbits(64))

        def seen() -> bool:
            return enemy.index in driver.perceiver.memory.last_seen  # type: ignore[union-attr]
    for _ in range(int(round(cap / world.dt))):
        world.step(None, [driver(world, me), IDLE])
        if seen():
            return world.t
    return cap


def cpu(arena, spec, kind: str, steps: int) -> float:
    """Mean seconds per simulated step spent by 8 drivers deciding."""
    world = World(arena.walls, [spec] * 8, arena.spawns, seed=1, bounds=arena.bounds)
    if kind == "agent":
        drivers = make_agents(world, "normal")
    else:
        drivers = [ScriptedDriver(random.Random(world.rng.getrandbits(64))) for _ in range(8)]
    tanks = world.tanks
    spent = 0.0
    for _ in range(steps):
        t0 = time.perf_counter()
        cmds = [d(world, t) for d, t in zip(drivers, tanks)]
        spent += time.perf_counter() - t0
        world.step(None, cmds)
    return spent / steps


class Gunner:
    """Stands, turns onto the exact intercept of tank ``target`` (its true state),
    fires when a shot now would pass within ``tolerance`` m of its centre."""

    def __init__(self, target: int, tolerance: float = 0.5) -> None:
        self.target, self.tolerance = target, tolerance

    def __call__(self, world, me) -> Command:
        t = world.tanks[self.target]
        v = me.spec.shell_speed
        sol = aim.intercept(me.x, me.z, me.vx, me.vz, t.x, t.z, t.vx, t.vz, v)
        if sol is None:
            return IDLE
        err = math.remainder(sol.heading - me.heading, 2.0 * math.pi)
        miss = aim.predicted_miss(me.x, me.z, me.vx, me.vz, me.heading, t.x, t.z, t.vx, t.vz, v)
        return Command(rotate=max(-1.0, min(1.0, 4.0 * err - 0.6 * me.omega)),
                       fire=miss < self.tolerance and me.reload <= 0.0)


class Target:
    """Faces tank ``shooter`` at ``distance`` m; ``mode`` "still", "strafing" or
    "dodging" (strafing, and ``dodge.Evasion`` with ``reaction``)."""

    def __init__(self, shooter: int, distance: float, mode: str, rng: random.Random, reaction: float = 0.25) -> None:
        self.shooter, self.distance, self.mode, self.rng = shooter, distance, mode, rng
        self.side, self.flip = 1.0, 0.0
        self.evasion = dodge.Evasion(reaction)
        self.eyes: Perceiver | None = None

    def __call__(self, world, me) -> Command:
        s = world.tanks[self.shooter]
        dx, dz = s.x - me.x, s.z - me.z
        err = math.remainder(math.atan2(dz, dx) - me.heading, 2.0 * math.pi)
        rotate = max(-1.0, min(1.0, 3.0 * err - 0.5 * me.omega))
        vf = me.vx * me.c + me.vz * me.s
        want = max(-4.0, min(4.0, 0.5 * (math.hypot(dx, dz) - self.distance)))
        advance = max(-1.0, min(1.0, 0.5 * (want - vf)))
        if self.mode == "still":
            return Command(advance=advance, rotate=rotate)
        if world.t >= self.flip:
            self.side, self.flip = -self.side, world.t + self.rng.uniform(3.0, 6.0)
        if self.mode == "dodging":
            if self.eyes is None:           # it sees every shell (the radar of the bot API)
                self.eyes = Perceiver(world, me.index, Senses(radar=True), 0)
            esc = self.evasion.command(world.t, self.eyes.state(world, me), self.eyes.shells(world, me))
            if esc is not None:
                return Command(advance=esc[0], rotate=rotate, strafe=esc[1])
        return Command(advance=advance, rotate=rotate, strafe=self.side)


DODGE_MODES = ("still", "strafing", "dodging")


def dodge_share(spec, distance: float, mode: str, seconds: float, seed: int = 0) -> tuple[int, int]:
    """(on-target shots, hits) of a :class:`Gunner` at a :class:`Target` ``distance`` m
    away on an open field, under the game's rules without spawn protection."""
    size = 400.0
    field = WallList(np.zeros((0, 2, 2)), np.zeros(0, np.int8), aux_rectangle(0.0, 0.0, size, size))
    rules = dataclasses.replace(DEFAULT_RULES, spawn_protection=0.0)
    c = size / 2
    world = World(field, [spec, spec], [(c, c, 0.0), (c + distance, c, math.pi)], seed=seed, rules=rules,
                  bounds=[[0.0, 0.0], [size, size]])
    world.tanks[0].place(c, c, 0.0)
    world.tanks[1].place(c + distance, c, math.pi)
    drivers = [Gunner(1), Target(0, distance, mode, random.Random(seed))]
    shots = hits = 0
    for _ in range(int(round(seconds / world.dt))):
        for e in world.step(None, [d(world, t) for d, t in zip(drivers, world.tanks)]):
            shots += e.kind == "shot" and e.tank == 0
            hits += e.kind == "hit" and e.tank == 0
        world.tanks[1].hp = world.tanks[1].spec.hit_points      # it must live to be shot at again
    return shots, hits


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--matches", type=int, default=100, help="duels per arena and difficulty (default 100)")
    ap.add_argument("--sight-runs", type=int, default=20, help="first-sight runs per arena and difficulty")
    ap.add_argument("--seconds", type=float, default=120.0, help="simulated seconds per duel (default 120)")
    ap.add_argument("--no-bound", dest="bound", action="store_false",
                    help="skip the bound (the same duels at normal for an agent told where the enemy is)")
    ap.add_argument("--cap", type=float, default=180.0, help="first-sight runs stop here [s]")
    ap.add_argument("--cpu-steps", type=int, default=3000)
    ap.add_argument("--arenas", default=",".join(bundled_names("arenas")),
                    help="comma-separated (default: every bundled arena)")
    ap.add_argument("--levels", default="easy,normal,hard")
    ap.add_argument("--vehicle", default="light")
    ap.add_argument("--dodge-seconds", type=float, default=90.0,
                    help="simulated seconds of shooting per distance and target (0: skip the dodging table)")
    ap.add_argument("--distances", default="10,20,30,40,50,60", help="dodging: target distances [m]")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    args = ap.parse_args(argv)
    spec = load_tank_spec(args.vehicle)
    arenas = [load_match_arena(a) for a in args.arenas.split(",")]
    levels = [lv for lv in args.levels.split(",") if lv]
    for lv in levels:
        if lv not in DIFFICULTIES:
            ap.error(f"--levels: {lv!r} is not one of {', '.join(DIFFICULTIES)}")
    t_start = time.perf_counter()
    rows = [row for arena in arenas for row in _arena_rows(arena, spec, levels, args, t_start)]
    cpu_rows = [{"arena": a.name, "agent_ms_per_step_8": 1e3 * cpu(a, spec, "agent", args.cpu_steps),
                 "baseline_ms_per_step_8": 1e3 * cpu(a, spec, "scripted", args.cpu_steps)} for a in arenas]
    dodge_rows = _dodge_rows(spec, args) if args.dodge_seconds > 0 else []
    out = {"vehicle": spec.name, "seconds_per_duel": args.seconds, "sight_runs": args.sight_runs,
           "sight_cap_s": args.cap, "baseline": "sim.driver.ScriptedDriver", "rows": rows, "cpu": cpu_rows,
           "rules": DEFAULT_RULES.to_dict(), "dodge": dodge_rows,
           "wall_clock_s": round(time.perf_counter() - t_start, 1)}
    if args.json:
        print(json.dumps(out))
    else:
        _print_tables(out, spec, args)
    return 0


def _arena_rows(arena, spec, levels: list[str], args, t_start: float) -> list[dict]:
    """One row per difficulty on ``arena``: duels against the baseline, first sight,
    and (normal) the bound of an agent told where the enemy is."""
    rows = []
    runs = range(args.sight_runs)
    base_sight = statistics.median(first_sight(arena, spec, k, None, args.cap) for k in runs)
    for lv in levels:
        res = [duel(arena, spec, k, lv, args.seconds) for k in range(args.matches)]
        wins = sum(r["kills"][0] > r["kills"][1] for r in res)
        losses = sum(r["kills"][0] < r["kills"][1] for r in res)
        minutes = args.matches * args.seconds / 60.0
        sights = [first_sight(arena, spec, k, lv, args.cap) for k in runs]
        bound = None
        if args.bound and lv == "normal":
            cheat = [duel(arena, spec, k, lv, args.seconds, Omniscient) for k in range(args.matches)]
            bound = sum(r["kills"][0] > r["kills"][1] for r in cheat) / args.matches
        rows.append({
            "arena": arena.name, "level": lv, "matches": args.matches,
            "wins": wins, "losses": losses, "draws": args.matches - wins - losses,
            "win_rate": wins / args.matches,
            "win_rate_decided": wins / (wins + losses) if wins + losses else None,
            "kills": sum(r["kills"][0] for r in res), "baseline_kills": sum(r["kills"][1] for r in res),
            "bumps_per_min": sum(r["bumps"][0] for r in res) / minutes,
            "baseline_bumps_per_min": sum(r["bumps"][1] for r in res) / minutes,
            "stuck": statistics.fmean(r["stuck"][0] for r in res),
            "baseline_stuck": statistics.fmean(r["stuck"][1] for r in res),
            "first_sight_median_s": statistics.median(sights),
            "first_sight_not_found": sum(s >= args.cap for s in sights),
            "baseline_first_sight_median_s": base_sight,
            "bound_win_rate": bound,
        })
        if not args.json:
            print(f"  {arena.name} {lv}: done ({time.perf_counter() - t_start:.0f} s)", file=sys.stderr)
    return rows


def _dodge_rows(spec, args) -> list[dict]:
    """On-target shots and hits at each distance on each kind of target."""
    rows = []
    for mode in DODGE_MODES:
        for dist in (float(v) for v in args.distances.split(",") if v):
            n, hits = dodge_share(spec, dist, mode, args.dodge_seconds)
            rows.append({"target": mode, "distance": dist, "on_target_shots": n, "hits": hits,
                         "avoided": (n - hits) / n if n else None})
    return rows


def _print_tables(out: dict, spec, args) -> None:
    """The duels, CPU and dodging tables of ``out`` for a reader."""
    rows, cpu_rows, dodge_rows = out["rows"], out["cpu"], out["dodge"]
    print(f"agent vs baseline (ScriptedDriver), {spec.name} tanks, 1-on-1 duels of {args.seconds:g} s, "
          f"{args.matches} per row; first sight: median of {args.sight_runs} runs, cap {args.cap:g} s")
    head = (f"{'arena':<10} {'level':<7} {'W-L-D':>11} {'win%':>5} {'win% dec':>8} {'kills':>9} "
            f"{'bumps/min':>11} {'stuck %':>11} {'1st sight s':>13} {'bound':>6}")
    print(head)
    print(f"{'':<10} {'':<7} {'':>11} {'':>5} {'':>8} {'us/base':>9} {'us/base':>11} {'us/base':>11} "
          f"{'us/base':>13} {'win%':>6}")
    print("-" * len(head))
    for r in rows:
        dec = f"{100 * r['win_rate_decided']:.0f}" if r["win_rate_decided"] is not None else "-"
        sight = f"{r['first_sight_median_s']:.0f}/{r['baseline_first_sight_median_s']:.0f}"
        bound = f"{100 * r['bound_win_rate']:.0f}" if r["bound_win_rate"] is not None else "-"
        print(f"{r['arena']:<10} {r['level']:<7} {r['wins']:>3}-{r['losses']}-{r['draws']:<3} "
              f"{100 * r['win_rate']:>5.0f} {dec:>8} {r['kills']:>4}/{r['baseline_kills']:<4} "
              f"{r['bumps_per_min']:>5.2f}/{r['baseline_bumps_per_min']:<5.2f} "
              f"{100 * r['stuck']:>5.1f}/{100 * r['baseline_stuck']:<5.1f} {sight:>13} {bound:>6}")
    print()
    print(f"{'arena':<10} {'8 agents ms/step':>17} {'8 baseline ms/step':>19}")
    for c in cpu_rows:
        print(f"{c['arena']:<10} {c['agent_ms_per_step_8']:>17.3f} {c['baseline_ms_per_step_8']:>19.3f}")
    if dodge_rows:
        dists = sorted({r["distance"] for r in dodge_rows})
        print()
        speed = DEFAULT_RULES.shell_speed or spec.shell_speed
        print(f"on-target shots avoided (shells {speed:g} m/s, {args.dodge_seconds:g} s at each distance; "
              "on-target shots in brackets)")
        print(f"{'target':<10}" + "".join(f"{d:>11.0f} m" for d in dists))
        for mode in DODGE_MODES:
            cells = []
            for d in dists:
                r = next(r for r in dodge_rows if r["target"] == mode and r["distance"] == d)
                cells.append(f"{100 * r['avoided']:>5.0f}% ({r['on_target_shots']:>3})" if r["avoided"] is not None
                             else f"{'-':>12}")
            print(f"{mode:<10}" + " ".join(f"{c:>12}" for c in cells))
    print("bound: win % of an agent told where the enemy is (the same duels, normal)")
    print("goals at normal: win rate >= 80 %, < 1 bump/min, stuck < 2 %; agents for 8 tanks < 1 ms per step")
    print(f"wall clock {out['wall_clock_s']:.0f} s")


if __name__ == "__main__":
    raise SystemExit(main())
