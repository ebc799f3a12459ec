"""Headless matches: load an arena and a vehicle, put bots (computer agents, or the
scripted baseline) in a world, run it for a number of simulated seconds as fast as
the machine allows, and report.

The report is one JSON-ready dict: ``arena``, ``seed``, ``seconds`` (simulated),
``rules`` (``sim.rules.Rules.to_dict``), ``match`` (limits, over, reason, winner,
standings: ``MatchState.to_dict``), ``tanks`` (name, kills, deaths, shots, hits,
wall_bumps, distance, position [x, z] at the end, ...), ``events`` (the timeline)
and, under ``timing`` only, everything that depends on the machine's speed.  A match
with a time or score limit ends there, before ``seconds`` if it comes first.  The same seed gives the same report apart from
``timing``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import ArenaError, TanktoolError, VehicleError
from .body import TankSpec
from .driver import make_drivers
from .rules import DEFAULT as DEFAULT_RULES, Rules
from .world import DT, World

REPO = Path(__file__).resolve().parent.parent.parent
DEFAULT_ARENAS = ("box", "paper2002", "maze")
DEFAULT_VEHICLES = ("light", "heavy")
#: where the bot positions are sampled for the picture's trails [s]
TRAIL_PERIOD = 0.25


@dataclass
class ArenaInfo:
    name: str
    walls: Any                    # WallList
    spawns: np.ndarray            # (k, 3) [x, z, heading], or (k, 4) with the ground's height y
    path: Path | None
    bounds: np.ndarray | None = None
    ground: Any = None            # sim.ground.Ground, or sim.flat_ground.FlatGround (None: flat at y = 0)
    vehicles: dict[str, Any] = field(default_factory=dict)   # the manifest's [vehicles]: what it was built for
    #: {vehicle: (clearance, (k, 4) spawns)} of the smaller vehicles' own grids (arena.toml [grids])
    grids: dict[str, Any] = field(default_factory=dict)

    def spawns_for(self, spec: Any) -> np.ndarray:
        """The spawn points of ``spec``'s vehicle (a TankSpec or a name): those of its own
        grid (a smaller vehicle's: surfaces only it reaches, such as a deck up a narrow
        ramp, included), else the arena's (where its largest vehicle fits)."""
        own = self.grids.get(spec if isinstance(spec, str) else getattr(spec, "name", None))
        return self.spawns if own is None else own[1]


@dataclass
class MatchResult:
    report: dict[str, Any]
    world: World
    arena: ArenaInfo
    trails: list[list[tuple[float, float]]] = field(default_factory=list)


def _bundle_dir(ref: str | Path, kind: str, defaults: tuple[str, ...]) -> Path:
    """A bundle folder from a path or a bundled name (``box`` -> the bundled arenas/box,
    inside the installed package or the checkout: tanktool/content.py).

    A bundled name is a plain folder name: ``../../etc`` is looked up as a path only,
    never below ``arenas/`` or ``vehicles/``."""
    from ..content import bundled_dir, bundled_names

    err = ArenaError if kind == "arenas" else VehicleError
    if not isinstance(ref, (str, Path)) or not str(ref) or "\0" in str(ref) or len(str(ref)) > 4096:
        raise err(f"{str(ref)[:80]!r}: not a {kind[:-1]} name or folder")
    p = Path(ref)
    try:
        if p.exists():
            return p
    except (OSError, ValueError):
        pass
    name = str(ref)
    if Path(name).name == name and name not in (".", ".."):
        home = bundled_dir(kind)
        for base in ([home] if home is not None else []) + [Path.cwd() / kind]:
            if (base / name).is_dir():
                return base / name
    have = bundled_names(kind)
    raise err(f"{ref}: no such {kind[:-1]} (a folder path, or one of: {', '.join(have) or 'none bundled yet'})")


def arena_dir(ref: str | Path) -> Path:
    """The folder of an arena given by path or bundled name (ArenaError when none)."""
    return _bundle_dir(ref, "arenas", DEFAULT_ARENAS)


def bundle_dir(ref: str | Path, kind: str) -> Path:
    """The folder of a bundle of ``kind`` ("arenas" or "vehicles") given by path or
    bundled name (ArenaError / VehicleError when none)."""
    return _bundle_dir(ref, kind, ())


def default_arena() -> str | None:
    """The first bundled arena that exists, or None."""
    from ..content import bundled_dir

    home = bundled_dir("arenas")
    for name in DEFAULT_ARENAS:
        if home is not None and (home / name / "walls.txt").is_file():
            return name
    return None


def default_vehicle() -> str | None:
    from ..content import bundled_dir

    home = bundled_dir("vehicles")
    for name in DEFAULT_VEHICLES:
        if home is not None and (home / name / "vehicle.toml").is_file():
            return name
    return None


def load_match_arena(ref: str | Path) -> ArenaInfo:
    """Walls, spawn points and bounds of an arena bundle (name or folder)."""
    from ..arena import load_arena

    from ..formats.vehicle_grids import vehicle_grids
    from .flat_ground import load_ground

    path = _bundle_dir(ref, "arenas", DEFAULT_ARENAS)
    bundle = load_arena(path)
    spawns = np.asarray(bundle.spawns, dtype=np.float64)
    spawns = spawns.reshape(len(spawns), -1) if spawns.size else np.zeros((0, 3))
    vehicles = bundle.toml.get("vehicles")
    grids = vehicle_grids(bundle.toml, Path(path) / "arena.toml")
    return ArenaInfo(str(bundle.name), bundle.walls, spawns, Path(path), np.asarray(bundle.bounds, float),
                     load_ground(bundle), vehicles if isinstance(vehicles, dict) else {}, grids)


#: a vehicle may be this much larger than the one an arena was built for [m] (rounding)
FIT_SLACK = 0.01


def choose_vehicle(info: ArenaInfo, requested: str | Path | None,
                   say: Callable[[str], None] | None = None) -> str | Path | None:
    """The vehicle to play ``info`` with: ``requested``, or the default one.

    An arena too small for the larger vehicles was built (its spawns, its navigation
    grid) for the largest one that fits: its manifest's ``[vehicles] radius`` and
    ``largest``.  A requested vehicle with a larger footprint is refused with a clear
    error (tanks would not fit its passages and spawns); when none was requested the
    largest that fits is taken instead of the default, and ``say`` is told."""
    ref = requested if requested is not None else default_vehicle()
    limit = info.vehicles.get("radius")
    if ref is None or not isinstance(limit, (int, float)) or isinstance(limit, bool) or not math.isfinite(limit):
        return ref
    from ..formats.vehicle_bundle import load_vehicle

    radius = float(load_vehicle(_bundle_dir(ref, "vehicles", DEFAULT_VEHICLES)).footprint_radius)
    if radius <= limit + FIT_SLACK:
        return ref
    largest = info.vehicles.get("largest")
    hint = f" (the largest that fits: --vehicle {largest})" if isinstance(largest, str) and largest else ""
    if requested is not None:
        raise VehicleError(f"{ref}: footprint radius {radius:.2f} m is too big for arena {info.name}, which was "
                           f"built for vehicles up to {limit:.2f} m{hint}; or re-import the arena for it")
    if not (isinstance(largest, str) and largest):
        raise VehicleError(f"arena {info.name} was built for vehicles up to {limit:.2f} m and the default "
                           f"vehicle {ref} is {radius:.2f} m: give a smaller one with --vehicle")
    if say is not None:
        say(f"arena {info.name} is too small for {ref} (footprint radius {radius:.2f} m > {limit:.2f} m): "
            f"playing with {largest}")
    return largest


def load_tank_spec(ref: str | Path | None) -> TankSpec:
    """A vehicle bundle (name or folder) as a TankSpec; None gives the built-in box
    tank (used only while no vehicle is bundled)."""
    if ref is None:
        return TankSpec.box("box")
    from ..formats.vehicle_bundle import load_vehicle

    return TankSpec.from_vehicle(load_vehicle(_bundle_dir(ref, "vehicles", DEFAULT_VEHICLES)))


def _r(v: float, nd: int = 3) -> float:
    v = round(float(v), nd)
    return 0.0 if v == 0.0 else v       # no "-0.0" in reports


#: who drives the bots: the computer agent (issue 7) or the old scripted stand-in (the baseline)
BOT_KINDS = ("agent", "scripted")


def make_bots(world: World, bot: str = "agent", difficulty: str = "normal") -> list:
    """One driver per tank: ``sim.agents.Agent`` at ``difficulty``, or ``ScriptedDriver``."""
    if bot == "scripted":
        return make_drivers(world)
    if bot == "agent":
        from .agents import DIFFICULTIES, make_agents

        if difficulty not in DIFFICULTIES:
            raise TanktoolError(f"--difficulty must be one of {', '.join(DIFFICULTIES)}, got {difficulty!r}")
        return make_agents(world, difficulty)
    raise TanktoolError(f"bots must be one of {', '.join(BOT_KINDS)}, got {bot!r}")


def match_rules(rules: Rules | dict | None = None, time_limit: float | None = None,
                score_limit: int | None = None) -> Rules:
    """The rules of a match: ``rules`` (a Rules, or its ``to_dict`` form; None: the
    game's defaults) with the limits given here (when not None) put in."""
    if isinstance(rules, dict):
        try:
            rules = Rules.from_dict(rules)
        except (TypeError, ValueError) as e:
            raise TanktoolError(str(e)) from None
    r = DEFAULT_RULES if rules is None else rules
    if time_limit is not None or score_limit is not None:
        try:
            r = r.with_limits(time_limit if time_limit is not None else r.time_limit,
                              score_limit if score_limit is not None else r.score_limit)
        except ValueError as e:
            raise TanktoolError(str(e).replace("rules: time_limit", "--time-limit")
                                .replace("rules: score_limit", "--score-limit")) from None
    return r


def run_match(arena: ArenaInfo, spec: TankSpec, bots: int = 4, seconds: float = 60.0, seed: int = 0,
              dt: float = DT, integrator: str = "semi-implicit",
              on_progress: Callable[[int], None] | None = None, progress_every: int = 120,
              bot: str = "agent", difficulty: str = "normal",
              wrap_drivers: Callable[[World, list], list] | None = None,
              rules: Rules | dict | None = None, time_limit: float | None = None,
              score_limit: int | None = None) -> MatchResult:
    """Run ``bots`` tanks for ``seconds`` of simulated time, driven by computer agents
    at ``difficulty`` (``bot="agent"``) or by the scripted baseline (``bot="scripted"``),
    under ``rules`` (default: the game's, ``sim.rules.DEFAULT``) with ``time_limit``
    and ``score_limit`` when given; a match that ends on a limit stops there.

    ``wrap_drivers(world, drivers) -> drivers`` may wrap or replace the drivers once
    they are made: sim/replay.py records the commands or plays a recording back."""
    if bots < 1:
        raise TanktoolError(f"--bots must be at least 1, got {bots}")
    if not (seconds > 0 and math.isfinite(seconds)):
        raise TanktoolError(f"--seconds must be a positive number, got {seconds}")
    names = [f"bot{i + 1}" for i in range(bots)]
    world = World(arena.walls, [spec] * bots, arena.spawns_for(spec), seed=seed, dt=dt, integrator=integrator,
                  names=names, bounds=arena.bounds, ground=arena.ground,
                  rules=match_rules(rules, time_limit, score_limit))
    drivers = make_bots(world, bot, difficulty)
    if wrap_drivers is not None:
        drivers = wrap_drivers(world, drivers)
    steps = int(round(seconds / dt))
    events = []
    trail_every = max(int(round(TRAIL_PERIOD / dt)), 1)
    trails: list[list[tuple[float, float]]] = [[t.position] for t in world.tanks]
    tanks = world.tanks
    # the bots' arena tables (agents' grids, sight) before the clock, as the arena's
    # loading is: steps/s is the match's pace, prepare_s what came before it
    ready = time.perf_counter()
    for d, t in zip(drivers, tanks):
        prepare = getattr(d, "prepare", None)
        if callable(prepare):
            prepare(world, t)
    start = time.perf_counter()
    done = 0
    for k in range(steps):
        commands = [d(world, t) for d, t in zip(drivers, tanks)]
        events.extend(world.step(None, commands))
        done = k + 1
        if (k + 1) % trail_every == 0:
            for tr, t in zip(trails, tanks):
                tr.append(t.position if t.alive else (math.nan, math.nan))
        if on_progress is not None and (k + 1) % progress_every == 0:
            on_progress(progress_every)
        if world.match.over:
            break
    wall = time.perf_counter() - start
    if on_progress is not None and (steps - done // progress_every * progress_every):
        on_progress(steps - done // progress_every * progress_every)
    steps = done
    report = make_report(world, arena.name, spec.name, seed, events)
    report["bots"] = bot
    report["difficulty"] = difficulty if bot == "agent" else None
    report["timing"] = {
        "wall_clock_s": round(wall, 4),
        "steps_per_second": round(steps / wall, 1) if wall > 0 else None,
        "realtime_factor": round(steps * dt / wall, 2) if wall > 0 else None,
        "prepare_s": round(start - ready, 4),
    }
    bot_report(report, drivers, world)
    return MatchResult(report, world, arena, trails)


def bot_report(report: dict[str, Any], drivers: list, world: World) -> None:
    """Bots' failures (deterministic: ``bot_errors`` per tank, when any failed) and
    their time per call (``timing.bots``: calls over the budget; it depends on the
    machine, so it never changes what happens)."""
    stats = [(t.name, getattr(d, "stats", None)) for d, t in zip(drivers, world.tanks)]
    errors = {name: st.errors for name, st in stats if st is not None and st.errors}
    if errors:
        report["bot_errors"] = errors
    timing = {name: st.timing() for name, st in stats if st is not None}
    if timing:
        report["timing"]["bots"] = timing


def make_report(world: World, arena: str, vehicle: str, seed: int, events: list) -> dict[str, Any]:
    """The match report (without ``timing``)."""
    names = world.names
    match = world.match
    tanks = []
    for t in world.tanks:
        x, z = t.position
        tanks.append({
            "name": t.name, "vehicle": t.spec.name, "kills": t.kills, "deaths": t.deaths,
            "shots": t.shots, "hits": t.hits, "wall_bumps": t.wall_bumps,
            "distance": _r(t.distance, 2), "position": [_r(x), _r(z)], "height": _r(t.y),
            "heading": _r(t.heading, 4),
            "hit_points": _r(max(t.hp, 0.0), 2), "alive": t.alive,
        })
    leader = match.winner if match.over else match.leader(world)
    return {
        "arena": arena,
        "vehicle": vehicle,
        "seed": seed,
        "seconds": _r(world.t, 6),
        "steps": world.steps,
        "dt": world.dt,
        "integrator": world.integrator,
        "winner": names[leader] if leader is not None and world.tanks[leader].kills > 0 else None,
        "rules": world.rules.to_dict(),
        "match": match.to_dict(world),
        "tanks": tanks,
        "events": [e.to_dict(names) for e in events],
    }


def format_report(report: dict[str, Any]) -> str:
    """The report as JSON text with one tank or event a line (diff- and grep-friendly)."""
    import json

    parts = []
    for key, value in report.items():
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            inner = ",\n  ".join(json.dumps(v) for v in value)
            parts.append(f" {json.dumps(key)}: [\n  {inner}\n ]")
        else:
            parts.append(f" {json.dumps(key)}: {json.dumps(value)}")
    return "{\n" + ",\n".join(parts) + "\n}\n"


def scoreboard(report: dict[str, Any]) -> str:
    """A fixed-width table of the tanks, best first, and, when the match has a time or
    score limit, a line saying whether it ended, how, and who won."""
    rows = sorted(report["tanks"], key=lambda d: (-d["kills"], d["deaths"]))
    head = f"{'tank':<8} {'kills':>5} {'deaths':>6} {'shots':>5} {'hits':>4} {'bumps':>5} {'distance':>9}  position"
    lines = [head, "-" * len(head)]
    for d in rows:
        x, z = d["position"]
        lines.append(f"{d['name']:<8} {d['kills']:>5} {d['deaths']:>6} {d['shots']:>5} {d['hits']:>4} "
                     f"{d['wall_bumps']:>5} {d['distance']:>8.1f}m  ({x:.1f}, {z:.1f})")
    m = report.get("match")
    if m and m["over"]:
        how = (f"score limit {m['score_limit']} reached" if m["reason"] == "score"
               else f"time limit {m['time_limit']:g} s reached")
        who = f"{m['winner']} wins" if m["winner"] else "a draw"
        lines.append(f"match over at {m['ended_at']:.2f} s: {how}, {who}")
    elif m and (m["time_limit"] is not None or m["score_limit"] is not None):
        lines.append(f"match not over after {report['seconds']:g} s (no limit reached)")
    return "\n".join(lines)
