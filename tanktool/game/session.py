"""A live game: one world, the player's tank, computer drivers, and what the front
ends need beyond the simulation (poses between steps, short-lived visual effects).

The simulation runs at its fixed step; :meth:`GameSession.step` keeps the previous
poses so renderers can draw at any fraction ``alpha`` between two steps (the
"interpolate the last two states" half of a fixed-timestep loop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from ..sim.commands import IDLE, Command
from ..sim.world import Event, World

#: (think_hz, aim spread in degrees, sight in m) of the scripted bots per difficulty; the
#: computer agents (``sim.agents``, the default) have their own levels of the same names
DIFFICULTY = {"easy": (4.0, 8.0, 60.0), "normal": (10.0, 3.0, 120.0), "hard": (20.0, 1.0, 160.0)}
#: seconds each kind of visual effect lasts
EFFECT_LIFE = {"flash": 0.12, "impact": 0.35, "explosion": 1.2}
#: a distinct colour per tank (RGB 0..255), the player's first
TANK_COLOURS = [(230, 200, 40), (210, 60, 50), (60, 120, 220), (60, 180, 90), (200, 90, 200),
                (240, 140, 40), (60, 200, 200), (150, 150, 150), (120, 80, 40), (250, 250, 250)]


def tank_colour(i: int) -> tuple[int, int, int]:
    return TANK_COLOURS[i % len(TANK_COLOURS)]


@dataclass
class Effect:
    kind: str            # "flash", "impact", "explosion"
    x: float
    y: float
    z: float
    t0: float
    #: a muzzle flash: the heading the gun points at; an impact: the unit (x, y, z) back
    #: towards the shooter (sparks fly that way)
    heading: float | None = None
    back: tuple[float, float, float] | None = None
    #: the tank it happened to: the shooter of a flash, the one hit or destroyed
    tank: int | None = None

    def age(self, t: float) -> float:
        """0 when it starts, 1 when it is over."""
        return (t - self.t0) / EFFECT_LIFE[self.kind]


def update_effects(effects: list[Effect], events: Sequence[Event], world: World) -> list[Effect]:
    """The effects still alive after a step, plus those its events start: a muzzle
    flash per shot, an impact per hit, an explosion per kill."""
    t = world.t
    out = [f for f in effects if f.age(t) < 1.0]
    for e in events:
        if e.kind == "shot":
            tank = world.tanks[e.tank]
            mx, my, mz = tank.spec.muzzle_local
            x, z = tank.to_world(mx, mz)
            out.append(Effect("flash", x, my + float(getattr(tank, "y", 0.0)), z, t, heading=tank.heading,
                              tank=e.tank))
        elif e.kind == "hit":
            victim = world.tanks[e.other] if 0 <= e.other < len(world.tanks) else None
            base = float(getattr(victim, "y", 0.0)) if victim is not None else 0.0
            height = 0.6 * victim.spec.height if victim is not None else 1.2
            shooter = world.tanks[e.tank] if 0 <= e.tank < len(world.tanks) else None
            back = None
            if shooter is not None:
                dx, dz = shooter.x - e.x, shooter.z - e.z
                n = math.hypot(dx, dz)
                back = (dx / n, 0.35, dz / n) if n > 1e-9 else None
            out.append(Effect("impact", e.x, base + height, e.z, t, back=back, tank=e.other))
        elif e.kind == "kill":
            victim = world.tanks[e.other] if 0 <= e.other < len(world.tanks) else None
            base = float(getattr(victim, "y", 0.0)) if victim is not None else 0.0
            top = 0.8 * victim.spec.height if victim is not None else 1.0
            out.append(Effect("explosion", e.x, base + top, e.z, t, tank=e.other))
    return out


#: events the HUD shows (kill feed, hit markers) stay this long [s]
FEED_S = 8.0


def update_feed(feed: list[Event], events: Sequence[Event], t: float) -> list[Event]:
    """The recent hits and kills the HUD shows: those of the last FEED_S seconds."""
    kept = [e for e in feed if t - e.t < FEED_S]
    kept.extend(e for e in events if e.kind in ("hit", "kill", "respawn"))
    return kept


Driver = Callable[[World, Any], Command]


class GameSession:
    """A match being played.

    Parameters
    ----------
    arena, vehicle : bundle folders or bundled names (as ``tanktool play --arena``)
    bots : number of computer opponents
    player : whether tank 0 is driven by the local player (else it is a bot too)
    bot : "agent" (``sim.agents.Agent`` at ``difficulty``) or "scripted" (the simple bot)
    drivers : optional drivers for the computer tanks, instead of ``bot``
    rules : the match's ``sim.rules.Rules`` (None: the default rules)
    bot_specs : bots (``play --bot``: names or FILE.py:Class) driving the first computer tanks
    """

    def __init__(self, arena: str | Path | None = None, vehicle: str | Path | None = None, bots: int = 3,
                 seed: int = 0, difficulty: str = "normal", player: bool = True,
                 drivers: Sequence[Driver] | None = None, bot: str = "agent", rules: Any = None,
                 bot_specs: Sequence[str] = ()) -> None:
        from ..errors import TanktoolError
        from ..sim.match import choose_vehicle, default_arena, load_match_arena, load_tank_spec, make_bots

        self._args = dict(arena=arena, vehicle=vehicle, bots=bots, seed=seed, difficulty=difficulty,
                          player=player, drivers=drivers, bot=bot, rules=rules, bot_specs=tuple(bot_specs))
        if difficulty not in DIFFICULTY:
            raise TanktoolError(f"difficulty must be one of {', '.join(DIFFICULTY)}, got {difficulty!r}")
        self.arena_ref = arena or default_arena()
        if self.arena_ref is None:
            raise TanktoolError("no arena given and none bundled under arenas/")
        self.info = load_match_arena(self.arena_ref)
        self.vehicle_ref = choose_vehicle(self.info, vehicle)   # refuses one too big for the arena
        self.spec = load_tank_spec(self.vehicle_ref)
        self.difficulty = difficulty
        n = bots + (1 if player else 0)
        if n < 1:
            raise TanktoolError("a match needs at least one tank")
        names = (["you"] if player else []) + [f"bot{i + 1}" for i in range(bots)]
        self.world = World(self.info.walls, [self.spec] * n, self.info.spawns_for(self.spec), seed=seed, names=names,
                           bounds=self.info.bounds, ground=getattr(self.info, "ground", None), rules=rules)
        self.player = 0 if player else None
        if drivers is not None:
            if len(drivers) != bots:
                raise TanktoolError(f"{len(drivers)} drivers for {bots} computer tanks")
            self.drivers: list[Driver | None] = ([None] if player else []) + list(drivers)
        else:
            self.drivers = list(make_bots(self.world, bot, difficulty))
            if bot == "scripted":
                hz, spread, sight = DIFFICULTY[difficulty]
                for d in self.drivers:
                    d.period, d.aim_spread, d.sight = 1.0 / hz, math.radians(spread), sight
            if player:
                self.drivers[0] = None
        if bot_specs:
            from ..sim.bots.lineup import lineup, seat

            if len(bot_specs) > bots:
                raise TanktoolError(f"{len(bot_specs)} bots named for {bots} computer tanks")
            self.drivers = seat(self.world, lineup(bot_specs), 1 if player else 0, self.drivers)
        self.effects: list[Effect] = []
        #: hits, kills and respawns of the last few seconds (kill feed, hit markers)
        self.feed: list[Event] = []
        self.prev = self._poses()
        self.last_events: list[Event] = []
        #: the tank the camera follows when there is no player (None: the first live one)
        self.follow: int | None = None
        #: set by :meth:`record`: every tank's commands, and the match's events for its report
        self.recorder: Any = None
        self.events: list[Event] = []
        #: a replay's session stops here (``game.replay_session``)
        self.max_steps: int | None = None

    # ------------------------------------------------------------------ stepping
    @property
    def dt(self) -> float:
        return self.world.dt

    @property
    def t(self) -> float:
        return self.world.t

    def _poses(self) -> list[tuple[float, ...]]:
        # (x, z, heading, y, pitch, roll): height and tilt when the simulation has them (2.5D)
        return [(*t.position, t.heading, float(getattr(t, "y", 0.0)), float(getattr(t, "pitch", 0.0)),
                 float(getattr(t, "roll", 0.0))) for t in self.world.tanks]

    def commands(self, player_command: Command = IDLE) -> list[Command]:
        w = self.world
        return [player_command if d is None else d(w, t) for d, t in zip(self.drivers, w.tanks)]

    def step(self, player_command: Command = IDLE) -> list[Event]:
        """One fixed simulation step; returns its events and records their effects."""
        self.prev = self._poses()
        w = self.world
        commands = self.commands(player_command)
        if self.recorder is not None:
            for i, c in enumerate(commands):
                self.recorder.record(w.steps, i, IDLE if c is None else c)
        events = w.step(None, commands)
        if self.recorder is not None:
            self.events.extend(events)
        self.effects = update_effects(self.effects, events, w)
        self.feed = update_feed(self.feed, events, w.t)
        self.last_events = events
        return events

    def restart(self) -> None:
        """Same arena, tanks and seed, from the start (drivers given by the caller are
        reused as they are).  A recording stops: call :meth:`record` again."""
        self.__init__(**self._args)

    # ------------------------------------------------------------------ recording
    def record(self) -> None:
        """Record this match from now on (call before the first step): the world's
        random state and every tank's commands, the player's included, as
        ``sim.replay`` records a headless match."""
        from ..errors import TanktoolError
        from ..sim.replay import Recorder

        if self.world.steps:
            raise TanktoolError("a match is recorded from its first step")
        self.recorder = Recorder()
        self.recorder.wrap(self.world, self.drivers)       # keeps the generator state; drivers stay ours
        self.events = []

    def report(self) -> dict[str, Any]:
        """The match report as ``run_match`` makes it, without ``timing`` (needs
        :meth:`record`, which keeps the events)."""
        from ..sim.match import make_report

        bot = self._args["bot"]
        report = make_report(self.world, self.info.name, self.spec.name, int(self._args["seed"]), self.events)
        report["bots"] = bot
        report["difficulty"] = self.difficulty if bot == "agent" else None
        return report

    def tape(self) -> Any:
        """The recording so far as a ``sim.replay.Replay`` that ``tanktool play
        --replay`` plays back headless (``run_match`` with the tape driving every tank)
        or in the window."""
        from ..errors import TanktoolError
        from ..sim.replay import match_header

        if self.recorder is None:
            raise TanktoolError("this match is not being recorded")
        w = self.world
        header = match_header(self.info, self.spec, w, seconds=w.steps * w.dt, seed=int(self._args["seed"]),
                              arena_ref=_stored_ref(self.arena_ref), vehicle_ref=_stored_ref(self.vehicle_ref),
                              options={"bot": self._args["bot"], "difficulty": self.difficulty},
                              winner=self.report().get("winner"), source="window", player=self.player)
        return self.recorder.replay(header)

    # ------------------------------------------------------------------ reading
    def pose(self, i: int, alpha: float = 1.0) -> tuple[float, float, float]:
        """(x, z, heading) of tank i's vehicle-frame origin, ``alpha`` of the way from the
        previous step to the current one."""
        x0, z0, h0 = self.prev[i][:3]
        t = self.world.tanks[i]
        x1, z1 = t.position
        h1 = t.heading
        if math.hypot(x1 - x0, z1 - z0) > 5.0:      # a respawn is a jump, not a glide
            return x1, z1, h1
        dh = math.remainder(h1 - h0, 2.0 * math.pi)
        return x0 + alpha * (x1 - x0), z0 + alpha * (z1 - z0), h0 + alpha * dh

    def pose3d(self, i: int, alpha: float = 1.0) -> tuple[float, float, float, float, float, float]:
        """(x, y, z, heading, pitch, roll) of tank i between the last two steps; y, pitch
        and roll are 0 until the simulation gives tanks a height and a tilt."""
        return pose3d(self, i, alpha)

    def shell_points(self, alpha: float = 1.0) -> np.ndarray:
        """(k, 3) positions of the shells in flight."""
        if not self.world.shells:
            return np.zeros((0, 3))
        return np.array([(s.px + alpha * (s.x - s.px), s.py + alpha * (s.y - s.py), s.pz + alpha * (s.z - s.pz))
                         for s in self.world.shells])

    def focus(self) -> int:
        """The tank the camera follows: the player, else ``follow``, else the first live tank."""
        if self.player is not None:
            return self.player
        if self.follow is not None and 0 <= self.follow < len(self.world.tanks):
            return self.follow
        return next((t.index for t in self.world.tanks if t.alive), 0)

    def focus_tank(self) -> Any:
        """The tank :meth:`focus` names."""
        return self.world.tanks[self.focus()]

    def scoreboard(self) -> list[tuple[str, int, int, float, bool]]:
        """(name, kills, deaths, hit points, alive) best first."""
        rows = [(t.name, t.kills, t.deaths, max(t.hp, 0.0), t.alive) for t in self.world.tanks]
        return sorted(rows, key=lambda r: (-r[1], r[2]))


def pose3d(session: Any, i: int, alpha: float = 1.0) -> tuple[float, float, float, float, float, float]:
    """A session's tank i as (x, y, z, heading, pitch, roll) ``alpha`` of the way from its
    previous step (sessions that keep only (x, z, heading) give the current tilt)."""
    x, z, h = session.pose(i, alpha)
    t = getattr(session, "world_all", session.world).tanks[i]     # a network match shows only some
    now = (float(getattr(t, "y", 0.0)), float(getattr(t, "pitch", 0.0)), float(getattr(t, "roll", 0.0)))
    prev = session.prev[i][3:6] if i < len(session.prev) and len(session.prev[i]) >= 6 else now
    if math.hypot(*(a - b for a, b in zip(t.position, session.prev[i][:2]))) > 5.0:
        prev = now                                    # a respawn is a jump
    y, pitch, roll = (a + alpha * (b - a) for a, b in zip(prev, now))
    return x, y, z, h, pitch, roll


def _stored_ref(ref: Any) -> str | None:
    """A bundle reference as a replay stores it: an existing path made absolute (so the
    replay plays from any folder), a bundled name as it is."""
    if ref is None:
        return None
    p = Path(ref)
    return str(p.resolve()) if p.exists() else str(ref)
