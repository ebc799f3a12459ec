"""Where to shoot from on relief.

The gun is the hull: on a slope it points up or down the slope with it, and from a
10 degree slope a tank 30 m away on level ground is missed by 5 m (``aim.height_miss``).
An agent that holds its fire for that (as it must: the shell would hit the hill or
fly over) would stand and stare for the rest of the fight; one that fires anyway
wastes its shots.  So when the pitch where it stands will not carry a shot onto the
enemy, it looks round it for a place that will: points on rings about it, each
judged facing the enemy -- the hull's pitch there from the ground's height a half
length ahead and behind (as the world tilts a tank), the shell's height at the enemy
from that pitch, a clear line of sight from there to the enemy and a clear flight
for the shell (``shell_clear``) -- and drives to the nearest such place with the gun
kept on the enemy, preferring one where the enemy's hull, turned to it, would shoot
over or under it (hull-down: on a crest that is often the place just behind it).

A place is only taken on the ground the agent stands on (within ``STEP`` m of its own
height, so not a deck above or below it) and on its navigation grid.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..bots.map import EYE
from . import aim as gun

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import View
    from ..bots.view import Vehicle
    from .perception import Sighting

#: the rings looked round on [m] and the points on each
RINGS = (3.0, 6.0, 10.0, 14.0)
POINTS = 12
#: a place more than this above or below where it stands is another level [m]
STEP = 2.5
#: a shot may pass this far over or under the enemy's body [m]
TOLERANCE = 0.25
#: the steepest rise a tank drives, as a slope (35 degrees)
MAX_RISE = 0.7


def pitch_at(view: "View", x: float, z: float, heading: float) -> tuple[float, float]:
    """(eye height, hull pitch) of our tank standing at (x, z) facing ``heading``: the
    pitch from the ground a half length ahead and behind (positive: nose up)."""
    m, v = view.map, view.me.vehicle
    half = 0.5 * (v.box[2] - v.box[0])
    c, s = math.cos(heading), math.sin(heading)
    # the map's eye height is its own (EYE over the ground); the gun is at ours
    eye = m.eye_at(x, z) - EYE + v.eye
    front, back = m.eye_at(x + c * half, z + s * half), m.eye_at(x - c * half, z - s * half)
    return eye, math.atan2(front - back, 2.0 * half)


def miss_from(view: "View", x: float, z: float, eye: float, pitch: float, s: "Sighting",
              ev: "Vehicle") -> float:
    """How far over or under the enemy's body a shot from (x, z) at ``eye`` height and
    ``pitch`` passes [m] (``aim.height_miss``)."""
    me = view.me
    d = math.hypot(s.x - x, s.z - z)
    return gun.height_miss(eye, pitch, me.vehicle.shell_speed, view.rules.shell_gravity, d, s.y, ev.height)


def shell_clear(view: "View", x: float, z: float, eye: float, pitch: float, s: "Sighting",
                moving: tuple[float, float, float] | None = None) -> bool:
    """Whether a shell from (x, eye, z) at ``pitch`` flies to the enemy without meeting
    the model first (a crest between can stop a shot the enemy's height would let
    through): the straight line to where it passes the enemy (the rules' gravity
    bends it by less than the tolerance over a duel's ranges).  ``moving``: (hull
    heading, vx, vz) of a tank firing on the move -- the shell keeps the tank's
    velocity across the ground, not up, so it climbs less steeply on the way in."""
    me = view.me
    v = me.vehicle.shell_speed
    cp = math.cos(pitch)
    d = math.hypot(s.x - x, s.z - z)
    if v <= 0.0 or cp <= 1e-6:
        return False
    mesh = getattr(view.map.ground, "mesh", None)
    if mesh is None:
        tau = d / (v * cp)
        y = eye + v * math.sin(pitch) * tau - 0.5 * view.rules.shell_gravity * tau * tau
        return not view.map.line_blocked(x, z, s.x, s.z, eye, y)
    # the model's own triangles, as the world stops a shell (sim.weapons): the sight
    # solid lets a line graze a crest (MARGIN deep, in cells): 48 of hard's 174 shells
    # at the hills' camper (seeds 0-11) went into a slope the sight test passed.  Up
    # to the enemy's near side (its own ground may rise under its middle)
    h, vx, vz = moving if moving is not None else (math.atan2(s.z - z, s.x - x), 0.0, 0.0)
    ux, uz = v * cp * math.cos(h) + vx, v * cp * math.sin(h) + vz
    ev = s.vehicle if s.vehicle is not None else me.vehicle
    tau = max(d - ev.radius, 0.0) / max(math.hypot(ux, uz), 1e-6)
    y = eye + v * math.sin(pitch) * tau - 0.5 * view.rules.shell_gravity * tau * tau
    return mesh.first_hit((x, eye, z), (x + ux * tau, y, z + uz * tau)) is None


def firing_spot(view: "View", s: "Sighting", valid) -> tuple[float, float] | None:
    """The place about us (``RINGS`` x ``POINTS``) from which a shot at ``s`` would pass
    through its body's height with nothing in the way; ``valid(x, z)`` says whether a
    place is on our grid.  Of the places on the nearest ring that has any, one where the
    enemy's own hull, turned to it where it stands, would shoot over or under us if
    there is one (hull-down: we hit, it cannot), else the one whose shot passes
    nearest the middle of its height.  None: no such place."""
    me, m = view.me, view.map
    ev = s.vehicle if s.vehicle is not None else me.vehicle
    eye_s = s.y + ev.eye
    for r in RINGS:
        good: list[tuple[bool, float, float, float, float, float]] = []
        # start across the line of fire (a strafe gets there soonest and dodges too)
        base = math.atan2(s.z - me.z, s.x - me.x) + 0.5 * math.pi
        for k in range(POINTS):
            a = base + 2.0 * math.pi * k / POINTS
            x, z = me.x + r * math.cos(a), me.z + r * math.sin(a)
            if not valid(x, z):
                continue
            eye, pitch = pitch_at(view, x, z, math.atan2(s.z - z, s.x - x))
            if abs(eye - me.eye) > STEP:
                continue
            miss = miss_from(view, x, z, eye, pitch, s, ev)
            if miss < TOLERANCE:
                good.append((not _exposed(view, s, ev, x, z, eye), -miss, x, z, eye, pitch))
        if not good:
            continue
        good.sort(reverse=True)
        clear = m.blocked_from(s.x, s.z, eye_s, [(x, z, eye) for *_, x, z, eye, _ in good])
        for (*_, x, z, eye, pitch), blocked in zip(good, clear):
            if blocked or m.walls_of(me.level).blocked(me.x, me.z, x, z):
                continue
            if shell_clear(view, x, z, eye, pitch, s):
                return x, z
    return None


def _exposed(view: "View", s: "Sighting", ev: "Vehicle", x: float, z: float, eye: float) -> bool:
    """Whether the enemy, turned to (x, z) where it stands, would put a shot through
    our height there (its hull's pitch from the ground; its size taken for ours)."""
    m, me = view.map, view.me
    half = 0.5 * (ev.box[2] - ev.box[0])
    h = math.atan2(z - s.z, x - s.x)
    c, sn = math.cos(h), math.sin(h)
    pitch = math.atan2(m.eye_at(s.x + c * half, s.z + sn * half) - m.eye_at(s.x - c * half, s.z - sn * half),
                       2.0 * half)
    d = math.hypot(x - s.x, z - s.z)
    ground = eye - me.vehicle.eye
    return gun.height_miss(s.y + ev.eye, pitch, ev.shell_speed, view.rules.shell_gravity, d, ground,
                           me.vehicle.height) < TOLERANCE


def rise(view: "View", s: "Sighting", sol: "gun.Solution") -> float:
    """How much higher the ground is where the enemy will be when the shell gets
    there than where it is [m] (a strafe across a 10 degree slope climbs 0.9 m in a
    second), no steeper than a tank climbs (another deck's surface is not its way)."""
    moved = math.hypot(sol.x - s.x, sol.z - s.z)
    if moved < 0.1:
        return 0.0
    up = view.map.eye_at(sol.x, sol.z) - view.map.eye_at(s.x, s.z)
    return max(-MAX_RISE * moved, min(MAX_RISE * moved, up))
