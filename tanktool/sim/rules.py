"""The rules of a match: the gun every tank carries, spawn protection, where tanks
(re)spawn, and when the match ends.  The same for every tank, whoever drives it
(keyboard, agent, network peer): the world applies them, nobody else.

Why these numbers (docs/simulation.md, "Rules", has the measurements): a shell that
is on target when fired should be dodgeable by a tank that moves well beyond about
40 m and not at close range.  A tank that faces its enemy (the gun is in the hull)
dodges by strafing, and its tracks' grip stops a strafe in about 0.15 s, so the best
dodge is to stop (or start) a strafe when the shot is fired: the shooter led the old
velocity.  Stopping from 7 m/s takes the tank about 2 m off the line in 0.45 s; with
a reaction of about 0.2 s a shell must take about 0.65 s over 40 m, so shells fly at
60 m/s, straight (no gravity: a 60 m/s shell would fall to the floor within 40 m),
up to ``shell_range``.  At 15 m the same shell arrives in 0.25 s: no time to dodge.

``Rules.classic()`` are the rules before issue 19 (each vehicle's own gun, shells
under gravity, no spread, no protection, spawns anywhere free): replays recorded
then carry no rules and play back under them, bit for bit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from .body import TankSpec
    from .world import World

GRAVITY = 9.81


@dataclass(frozen=True)
class Rules:
    """A match's rules.  Times in seconds, distances in metres, angles in radians.

    shell_speed : muzzle speed of every gun [m/s] (the shell also keeps the shooter's
        velocity); None: each vehicle's own ``shell_speed``
    shell_range : a shell that has flown this far in (x, z) is spent [m]
    shell_gravity : downward acceleration of shells [m/s^2] (0: they fly straight)
    spread : standard deviation of each shot's random angular dispersion [rad]
    damage : hit points a hit takes; None: each vehicle's ``shell_damage``
    reload : seconds between shots; None: each vehicle's ``fire_interval``
    spawn_protection : a tank takes no damage for this long after it (re)spawns,
        until it fires [s] (0: none)
    hidden_spawns : (re)spawn out of the live enemies' line of sight when a free
        spawn point allows it
    time_limit : the match ends at this simulated time [s] (None: never)
    score_limit : the match ends when a tank reaches this many kills (None: never)
    """

    shell_speed: float | None = 40.0
    shell_range: float = 160.0
    shell_gravity: float = 0.0
    spread: float = math.radians(0.4)
    damage: float | None = None
    reload: float | None = None
    spawn_protection: float = 3.0
    hidden_spawns: bool = True
    time_limit: float | None = None
    score_limit: int | None = None

    def __post_init__(self) -> None:
        def check(name: str, ok: bool, what: str) -> None:
            if not ok:
                raise ValueError(f"rules: {name} must be {what}, got {getattr(self, name)!r}")

        for name in ("shell_speed", "damage", "reload", "time_limit"):
            v = getattr(self, name)
            if v is not None:
                check(name, isinstance(v, (int, float)) and math.isfinite(v) and v > 0, "a positive number or None")
        check("shell_range", isinstance(self.shell_range, (int, float)) and self.shell_range > 0
              and not math.isnan(self.shell_range), "a positive number (inf: no limit)")
        for name in ("shell_gravity", "spread", "spawn_protection"):
            v = getattr(self, name)
            check(name, isinstance(v, (int, float)) and math.isfinite(v) and v >= 0, "a number >= 0")
        if self.shell_gravity == 0.0 and math.isinf(self.shell_range):
            raise ValueError("rules: shells without gravity need a finite shell_range")
        if self.score_limit is not None:
            check("score_limit", isinstance(self.score_limit, int) and not isinstance(self.score_limit, bool)
                  and self.score_limit >= 1, "a whole number >= 1 or None")

    @classmethod
    def classic(cls, **changes: Any) -> "Rules":
        """The rules before issue 19: each vehicle's gun, shells under gravity with no
        range limit, no spread, no spawn protection, spawns anywhere free."""
        base = dict(shell_speed=None, shell_range=math.inf, shell_gravity=GRAVITY, spread=0.0,
                    spawn_protection=0.0, hidden_spawns=False)
        base.update(changes)
        return cls(**base)

    def with_limits(self, time_limit: float | None = None, score_limit: int | None = None) -> "Rules":
        return dataclasses.replace(self, time_limit=time_limit, score_limit=score_limit)

    def arm(self, spec: "TankSpec") -> "TankSpec":
        """``spec`` carrying these rules' gun (the same object when nothing changes)."""
        changes = {}
        for rule, field in (("shell_speed", "shell_speed"), ("damage", "shell_damage"), ("reload", "fire_interval")):
            v = getattr(self, rule)
            if v is not None and float(v) != float(getattr(spec, field)):
                changes[field] = float(v)
        return dataclasses.replace(spec, **changes) if changes else spec

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (an infinite range is written as null)."""
        d = dataclasses.asdict(self)
        if math.isinf(d["shell_range"]):
            d["shell_range"] = None
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "rules") -> "Rules":
        """From :meth:`to_dict`'s form; unknown keys or bad values raise ValueError
        naming the key."""
        if not isinstance(d, dict):
            raise ValueError(f"{where}: expected a table of rules, got {type(d).__name__}")
        names = {f.name for f in dataclasses.fields(cls)}
        bad = sorted(set(d) - names)
        if bad:
            raise ValueError(f"{where}: unknown rule {bad[0]!r}")
        kw = dict(d)
        if "shell_range" in kw and kw["shell_range"] is None:
            kw["shell_range"] = math.inf
        return cls(**kw)


#: the rules of every world made without any (the game's)
DEFAULT = Rules()


@dataclass
class Standing:
    """One tank's line of the scoreboard."""

    index: int
    name: str
    kills: int
    deaths: int
    place: int


class MatchState:
    """Where a match stands: whether it is over, why, who won.  ``World.match``.

    over : the match has ended (the world no longer steps)
    reason : "time" or "score" once over, else None
    ended_at : simulated time it ended [s], or None
    winner : index of the tank with the most kills (fewest deaths breaking a tie)
        once over; None while it runs, and for a draw (equal at the top)
    """

    def __init__(self, time_limit: float | None = None, score_limit: int | None = None) -> None:
        self.time_limit = time_limit
        self.score_limit = score_limit
        self.over = False
        self.reason: str | None = None
        self.ended_at: float | None = None
        self.winner: int | None = None

    def time_left(self, t: float) -> float | None:
        """Seconds until the time limit (None: no time limit)."""
        return None if self.time_limit is None else max(self.time_limit - t, 0.0)

    def standings(self, world: "World") -> list[Standing]:
        """The tanks best first: most kills, then fewest deaths; equal tanks share a place."""
        order = sorted(world.tanks, key=lambda t: (-t.kills, t.deaths, t.index))
        out: list[Standing] = []
        for k, t in enumerate(order):
            same = out and (out[-1].kills, out[-1].deaths) == (t.kills, t.deaths)
            out.append(Standing(t.index, t.name, t.kills, t.deaths, out[-1].place if same else k + 1))
        return out

    def leader(self, world: "World") -> int | None:
        """The tank alone at the top of the standings, or None (a tie)."""
        s = self.standings(world)
        if not s or (len(s) > 1 and s[1].place == 1):
            return None
        return s[0].index

    def check(self, world: "World") -> str | None:
        """End the match if a limit is reached now; the reason, or None."""
        if self.over:
            return None
        reason = None
        if self.score_limit is not None and any(t.kills >= self.score_limit for t in world.tanks):
            reason = "score"
        elif self.time_limit is not None and world.t >= self.time_limit - 1e-9:
            reason = "time"
        if reason is not None:
            self.over, self.reason, self.ended_at = True, reason, world.t
            self.winner = self.leader(world)
        return reason

    def to_dict(self, world: "World") -> dict[str, Any]:
        """For the report: limits, whether it is over, why, when, the winner's name and
        the standings."""
        names = world.names
        return {
            "time_limit": self.time_limit, "score_limit": self.score_limit, "over": self.over,
            "reason": self.reason, "ended_at": None if self.ended_at is None else round(self.ended_at, 6),
            "winner": None if self.winner is None else names[self.winner],
            "standings": [{"place": s.place, "name": s.name, "kills": s.kills, "deaths": s.deaths}
                          for s in self.standings(world)],
        }
