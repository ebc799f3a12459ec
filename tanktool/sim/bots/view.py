"""What a bot perceives: the values of one tank's ``View``.

Everything here is a plain value (frozen dataclasses of numbers and tuples), made by
the game from the world each time the bot acts (``perceive.Perceiver``), so a bot can
keep any of it without holding the world: its own tank (:class:`TankState`), the kind
of vehicle a tank is (:class:`Vehicle`), enemies in sight (:class:`Sighting`), what it
hears (:class:`Heard`), shells it sees (:class:`ShellSeen`), its own memory
(:class:`Memory`) and the senses it perceives with (:class:`Senses`).
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..commands import IDLE, Command

if TYPE_CHECKING:  # pragma: no cover
    from ..body import TankSpec
    from ..rules import Rules
    from ..world import Event
    from .map import Map


@dataclass(frozen=True, slots=True)
class Vehicle:
    """A kind of tank, as armed by the match's rules (SI units, angles in radians).

    ``box`` is the footprint's (xmin, zmin, xmax, zmax) about the centre of mass in the
    vehicle frame (+x forward, +z right); ``radius`` the footprint's radius; ``eye``
    the gun's height over the tank's base (where it sees from and is seen at)."""

    name: str
    radius: float
    box: tuple[float, float, float, float]
    height: float
    eye: float
    mass: float
    inertia: float
    engine_force: float
    strafe_force: float
    turn_torque: float
    turn_rate: float
    friction: float
    grip: float
    top_speed: float
    hit_points: float
    shell_speed: float
    shell_damage: float
    fire_interval: float

    @classmethod
    def of(cls, spec: "TankSpec") -> "Vehicle":
        return cls(spec.name, float(spec.radius), tuple(float(v) for v in spec.box), float(spec.height),  # type: ignore[arg-type]
                   float(spec.muzzle_local[1]), spec.mass, spec.inertia, spec.engine_force, spec.strafe_force,
                   spec.turn_torque, spec.turn_rate, spec.friction, spec.grip, spec.top_speed, spec.hit_points,
                   spec.shell_speed, spec.shell_damage, spec.fire_interval)


@dataclass(frozen=True, slots=True)
class TankState:
    """The bot's own tank now: position (x, z) and the height ``y`` of its base, heading
    (forward = (cos, sin) in (x, z)), velocity [m/s], turn rate ``omega`` [rad/s], the
    hull's ``pitch`` and ``roll`` on relief, the ground ``level`` it stands on, hit
    points, seconds until the gun is loaded (``reload``), its score (what the HUD
    shows), the seconds of spawn protection left and its vehicle."""

    index: int
    name: str
    x: float
    z: float
    y: float
    heading: float
    vx: float
    vz: float
    omega: float
    pitch: float
    roll: float
    level: int
    hp: float
    alive: bool
    reload: float
    kills: int
    deaths: int
    shots: int
    hits: int
    protected: float
    vehicle: Vehicle

    @property
    def c(self) -> float:
        return math.cos(self.heading)

    @property
    def s(self) -> float:
        return math.sin(self.heading)

    @property
    def eye(self) -> float:
        """World height of its gun (where it sees from)."""
        return self.y + self.vehicle.eye

    def speed(self) -> float:
        return math.hypot(self.vx, self.vz)


@dataclass(frozen=True, slots=True)
class Sighting:
    """One enemy seen at time ``t``: its index, centre and velocity then, distance,
    which way its hull (and gun) points, the height it stands at, the seconds of
    spawn protection it has left (a player sees its shield) and its vehicle."""

    index: int
    x: float
    z: float
    vx: float
    vz: float
    t: float
    distance: float
    heading: float = 0.0
    y: float = 0.0
    protected: float = 0.0
    vehicle: Vehicle | None = None


@dataclass(frozen=True, slots=True)
class Heard:
    """A shot (or, ``engine`` True, a moving tank) heard at time ``t`` from around
    (x, z) (noisy), at about height ``y`` (which floor it came from)."""

    x: float
    z: float
    t: float
    engine: bool = False
    y: float | None = None


@dataclass(frozen=True, slots=True)
class ShellSeen:
    """An enemy shell in flight: ``key`` names it for as long as it flies (its owner
    and the step it was fired in), position and velocity now."""

    key: tuple[int, int]
    owner: int
    x: float
    y: float
    z: float
    vx: float
    vy: float
    vz: float


@dataclass(frozen=True, slots=True)
class Senses:
    """How a tank perceives (times in seconds, distances in metres, angles in radians).

    half_angle, vision_range : the vision cone about the heading; an enemy in it is
        seen when nothing solid stands between the two guns
    hearing_radius : gunshots within it are heard, placed with Gaussian noise of
        ``hearing_noise`` x the distance
    engine_radius : moving tanks within it are heard through walls (full radius from
        6 m/s, half of it at a crawl, nothing below 0.5 m/s), with the same noise
    radar : BZFlag's radar: where every live tank and every shell is, whether seen or
        not (the yardstick robot's; a bot that asks for it says so)

    A bot may ask for less than ``LIMITS`` (a weaker opponent), never for more: the
    game keeps each value within them."""

    half_angle: float = math.radians(60.0)
    vision_range: float = 160.0
    hearing_radius: float = 120.0
    engine_radius: float = 40.0
    hearing_noise: float = 0.15
    radar: bool = False

    def limited(self) -> "Senses":
        """These senses kept within ``LIMITS`` (a value past a limit becomes the limit)."""
        lim = LIMITS

        def cap(v: Any, top: float) -> float:
            v = float(v)
            return top if not math.isfinite(v) or v > top else max(v, 0.0)

        return Senses(cap(self.half_angle, lim.half_angle), cap(self.vision_range, lim.vision_range),
                      cap(self.hearing_radius, lim.hearing_radius), cap(self.engine_radius, lim.engine_radius),
                      max(float(self.hearing_noise), lim.hearing_noise) if math.isfinite(self.hearing_noise)
                      else lim.hearing_noise, bool(self.radar))


#: the most any bot perceives (and the senses of a bot that declares none)
LIMITS = Senses()


@dataclass
class Memory:
    """What the tank remembers of other tanks, kept for the bot by the game: where each
    enemy was last seen (``last_seen``: index -> :class:`Sighting`), and the latest shot
    or engine heard (``heard``).  It is the bot's own: forgetting is allowed."""

    last_seen: dict[int, Sighting] = field(default_factory=dict)
    heard: Heard | None = None

    def forget(self, index: int) -> None:
        self.last_seen.pop(index, None)


@dataclass(frozen=True, slots=True)
class View:
    """What one tank perceives when its bot acts (``Bot.act(view)``).

    t, dt, step : simulated time [s], the world's step length [s] and step number
    me : its own tank (:class:`TankState`)
    seen : live enemies in its vision cone and line of sight now, nearest first
    heard : shots heard since it last acted (nearest first)
    engines : moving enemies heard now (nearest first)
    shells : enemy shells it sees (in the cone, in range, in line of sight; every
        enemy shell with radar)
    radar : every live enemy, seen or not (empty unless ``senses.radar``)
    events : what happened to it since it last acted (``sim.world.Event``: its shots,
        hits it scored and took, kills it made and suffered, its wall bumps and
        respawns) and every kill of the match (the kill feed; others' kills without
        a position)
    memory : its :class:`Memory` (updated with ``seen`` and ``heard`` before the call)
    map : the arena (``map.Map``: grid, paths, lines of sight, walls)
    rules : the match's rules (``sim.rules.Rules``)
    senses : the senses it perceives with (its own, within ``LIMITS``)
    rng : its own seeded generator (use it, not ``random``, and matches replay exactly)
    """

    t: float
    dt: float
    step: int
    me: TankState
    seen: tuple[Sighting, ...]
    heard: tuple[Heard, ...]
    engines: tuple[Heard, ...]
    shells: tuple[ShellSeen, ...]
    radar: tuple[Sighting, ...]
    events: tuple["Event", ...]
    memory: Memory
    map: "Map"
    rules: "Rules"
    senses: Senses
    rng: random.Random


class Bot:
    """The optional base class of a bot: any class with ``act(self, view) -> Command``
    is one.

    Class attributes a bot may set: ``senses`` (:class:`Senses`: what it perceives;
    default ``LIMITS``) and ``think_hz`` (how many times a second ``act`` is called;
    None: every step; between calls its last command is held, as a player holds a
    key).  ``debug()`` may return what the game's top view draws over its tank:
    ``{"state": str, "path": [(x, z), ...]}``."""

    senses: Senses = LIMITS
    think_hz: float | None = None

    def act(self, view: View) -> Command:
        return IDLE

    def debug(self) -> dict[str, Any]:
        return {}
