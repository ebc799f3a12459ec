"""How good an agent is: the difficulty levels (easy, normal, hard).

A level sets what the agent perceives (vision range, hearing radius, engine hearing:
its ``Senses``), how fast it reacts and thinks, how well it aims and dodges, and how
it fights (distance, cover, hedging against a dodge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..bots import Senses

@dataclass(frozen=True)
class Difficulty:
    """How good an agent is.  Times in seconds, angles in radians, distances in metres."""

    name: str
    reaction: float
    aim_noise: float
    vision_range: float
    hearing_radius: float
    think_hz: float
    engine_radius: float = 0.0
    #: how much of the intercept lead it takes (0: aims at where the enemy is)
    lead: float = 1.0
    #: fires when a shot now would pass within this fraction of the enemy's half width
    fire_tolerance: float = 0.6
    #: notices a shell flying at it this long after it comes into view (inf: never dodges)
    dodge_reaction: float = math.inf
    #: the distance it fights at when it can choose [m]
    engage: float = 30.0
    #: and against an enemy standing still (it cannot dodge; we can, from afar) [m]
    stand_off: float = 30.0
    #: aims between where the enemy goes on and where it is if it stops this long after
    #: the shot (the stop that dodges); 0: the plain intercept [s]
    hedge: float = 0.0
    #: waits this long after its gun is loaded before it fires again (a newcomer's
    #: hesitation) [s]
    trigger: float = 0.0
    #: explores for what it has not seen (else: the paper's wander heuristic only)
    explore: bool = True
    #: holds vantage points and, leading, hiding places (``Agent(watch=...)`` too)
    watch: bool = True
    #: fights like a player who knows cover: closes in on a known enemy with the gun
    #: on it, hunts a camper, goes back behind the corner it came from while reloading
    #: (``scoot``: no level), breaks off a fight it is losing (``break_off``: no level)
    cover: bool = False
    #: with ``cover``: goes back behind the corner it came round while it reloads
    #: (False: keeps strafing.  No level does: a strafe builds up at about 1.5 m/s^2,
    #: so a tank that shuttles to cover hardly moves across the line of fire: hard's
    #: median sideways speed in its fights with the camper in the box was 0.5 m/s with
    #: it, 1.5 without; normal with it drove 17 m in the first demo, play --headless
    #: --seconds 10 --bots 2, without it 22 m)
    scoot: bool = False
    #: with ``cover``: breaks off a fight it is losing (the ``losing`` row: to cover).
    #: No level does: hard against the robot and the duellist on box and paper2002 (8
    #: duels each) won 5-7 of 8 with it and 7 of 8 without, normal against the robot on
    #: box, paper2002 and maze (6 each) 7-6-5 with it and 12-2-4 without; most deaths
    #: came while it drove off with the enemy hitting its back
    break_off: bool = False
    #: lies in wait for an enemy heard coming (its engine within ``combat.WAIT_NEAR`` m,
    #: behind cover): stands with the gun on where it comes into sight, the first
    #: shot its own (False: goes looking for it, and meets it round the corner with
    #: the gun wherever the way pointed it)
    wait: bool = False
    #: on relief, breaks off (Evade: out of the enemy's sight, then searches) when no
    #: shot of its own carries onto the enemy for ``combat.OUTGUNNED`` s and it is hit
    #: meanwhile (False: drives on to a place whence a shot would carry, under fire)
    outgunned: bool = False
    #: hunts by where the enemy probably is (``belief``: spawn points, sightings, sounds,
    #: spread at a tank's pace, minus what it looked at) rather than by what it has not
    #: seen lately alone
    hunt: bool = False
    #: on relief, drives to where the hull's pitch carries a shot onto the enemy when it
    #: does not where it stands (``relief``; False: holds its fire and stares)
    relief: bool = True

    def senses(self, half_angle: float = math.radians(60.0)) -> Senses:
        """What an agent of this level perceives."""
        return Senses(half_angle, self.vision_range, self.hearing_radius, self.engine_radius)


DIFFICULTIES: dict[str, Difficulty] = {
    "easy": Difficulty("easy", reaction=1.0, aim_noise=math.radians(9.0), vision_range=60.0,
                       hearing_radius=80.0, think_hz=8.0, engine_radius=40.0, lead=0.3, fire_tolerance=1.2,
                       dodge_reaction=math.inf, engage=25.0, stand_off=25.0, watch=False, trigger=1.6),
    # normal hedges and lies in wait as hard does (decisions, not reflexes: its reaction,
    # aim, dodging and vision stay weaker); against the robot, 48 duels each, the fort
    # 20-6-22 -> 28-4-16, the hills 18-20-10 -> 19-14-15 (docs/agents.md, sixth round)
    "normal": Difficulty("normal", reaction=0.3, aim_noise=math.radians(1.5), vision_range=90.0,
                         hearing_radius=80.0, think_hz=15.0, engine_radius=35.0, lead=1.0, fire_tolerance=0.7,
                         dodge_reaction=0.45, engage=40.0, stand_off=45.0, hedge=0.35, cover=True, wait=True),
    "hard": Difficulty("hard", reaction=0.1, aim_noise=math.radians(0.3), vision_range=130.0,
                       hearing_radius=120.0, think_hz=20.0, engine_radius=40.0, lead=1.0, fire_tolerance=0.5,
                       dodge_reaction=0.25, engage=50.0, stand_off=55.0, hedge=0.35, cover=True, wait=True,
                       outgunned=True, hunt=True),
}


def difficulty(name: str | Difficulty) -> Difficulty:
    """A difficulty by name (easy, normal, hard)."""
    if isinstance(name, Difficulty):
        return name
    try:
        return DIFFICULTIES[name]
    except KeyError:
        raise ValueError(f"difficulty must be one of {', '.join(DIFFICULTIES)}, got {name!r}") from None
