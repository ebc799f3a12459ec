"""Dodging shells: which shells will hit, and which way to drive so that they miss.

A shell flies straight (``Rules.shell_gravity`` is 0 in the game's rules), so once
it is seen its path is known.  Whether it hits depends on where the tank will be
when the shell passes, and that depends on the command held until then: the tank's
forward and sideways motion is predicted here with the world's own force laws
(engine and strafe with their fade near top speed, rolling drag, the tracks' grip
that kills a sideways slide at 8/s), heading held, which is what an aiming tank
does.  The escape is the command, among full forward / none / full reverse times
full left / none / full right, that keeps the shell farthest outside the hull
(``miss``, the clearance between the shell's line and the footprint; negative: a
hit).  Stopping a strafe is usually the best dodge: the grip stops a 7 m/s strafe in
about 0.15 s, and the shooter led the old velocity.

Used by the agents (``sim.agents``) and the yardsticks (``sim.agents.robots``) on
what their view shows (``sim.bots``: the tank's own state, the shells it sees as
values named by a stable key); measured by ``bench/bots.py`` (the share of
on-target shots a dodging tank avoids, by distance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Iterable, Sequence

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import ShellSeen, TankState, Vehicle

#: prediction step [s]
STEP = 1.0 / 60.0
#: shells arriving later than this are not dodged yet [s]
HORIZON = 2.5
#: the candidate escapes: (advance, strafe)
ESCAPES: tuple[tuple[float, float], ...] = tuple((a, s) for a in (0.0, 1.0, -1.0)
                                                 for s in (0.0, 1.0, -1.0, 0.5, -0.5))
#: an escape clearing every shell by this much [m] is safe: among the safe ones the tank
#: keeps the most of its sideways speed (it dodges the next shell with it)
SAFE = 0.4


@dataclass(frozen=True)
class Threat:
    """A shell that will hit if nothing changes: when it arrives [s from now] and by
    how much it would miss (negative: inside the hull) on the present course."""

    shell: "ShellSeen"
    arrives: float
    miss: float


def half_extent(tank: "TankState", direction: float) -> float:
    """Half the width of the tank's footprint box seen along ``direction`` [rad]."""
    return half_extent_at(tank.vehicle, tank.heading, direction)


def half_extent_at(spec: "Vehicle", heading: float, direction: float) -> float:
    """Half the width, seen along ``direction``, of the footprint box of a tank of
    ``spec`` facing ``heading`` [rad]."""
    bx0, bz0, bx1, bz1 = spec.box
    a = direction - heading
    return 0.5 * (bx1 - bx0) * abs(math.sin(a)) + 0.5 * (bz1 - bz0) * abs(math.cos(a))


def course(tank: "TankState", advance: float, strafe: float, duration: float,
           step: float = STEP) -> list[tuple[float, float, float]]:
    """(t, x, z) of the tank's centre every ``step`` s for ``duration`` s while it holds
    ``advance`` and ``strafe`` with its heading held (the world's force laws)."""
    sp = tank.vehicle
    c, s = math.cos(tank.heading), math.sin(tank.heading)
    vf = tank.vx * c + tank.vz * s
    vr = -tank.vx * s + tank.vz * c
    m, top = sp.mass, sp.top_speed
    strafe_top = 0.5 * top
    mu, grip = min(sp.friction, 1.0 / step), min(sp.grip, 1.0 / step)
    ea, sa = sp.engine_force / m, sp.strafe_force / m
    x = z = 0.0
    out = [(0.0, tank.x, tank.z)]
    n = max(int(math.ceil(duration / step)), 1)
    for k in range(n):
        af = -mu * vf
        if advance:
            fade = 20.0 * (1.0 - (vf if advance > 0 else -vf) / top)
            af += ea * advance * (0.0 if fade < 0.0 else 1.0 if fade > 1.0 else fade)
        lo, hi = (0.0, strafe * strafe_top) if strafe >= 0.0 else (strafe * strafe_top, 0.0)
        slide = vr - (lo if vr < lo else hi if vr > hi else vr)
        ar = -mu * vr - grip * slide
        if strafe:
            fade = 20.0 * (1.0 - (vr if strafe > 0 else -vr) / strafe_top)
            ar += sa * strafe * (0.0 if fade < 0.0 else 1.0 if fade > 1.0 else fade)
        vf += af * step
        vr += ar * step
        x += vf * step
        z += vr * step
        out.append(((k + 1) * step, tank.x + x * c - z * s, tank.z + x * s + z * c))
    return out


def clearance(tank: "TankState", shell: "ShellSeen", path: Sequence[tuple[float, float, float]]) -> float:
    """How far the shell passes outside the footprint (negative: it hits) if the tank
    follows ``path``: the least distance between the shell and the tank's centre over
    the path, less the footprint's half extent across the shell's line."""
    ext = half_extent(tank, math.atan2(shell.vz, shell.vx))
    best = math.inf
    prev = None
    for t, x, z in path:
        sx, sz = shell.x + shell.vx * t, shell.z + shell.vz * t
        d = math.hypot(sx - x, sz - z)
        if d < best:
            best = d
        elif prev is not None and d > prev:
            break                 # past the closest approach: it only grows from here
        prev = d
    return best - ext


def arrival(tank: "TankState", shell: "ShellSeen") -> tuple[float, float]:
    """(time of closest approach from now [s], distance then [m]) of ``shell`` to the
    tank's centre, both moving as they move now."""
    rx, rz = shell.x - tank.x, shell.z - tank.z
    vx, vz = shell.vx - tank.vx, shell.vz - tank.vz
    v2 = vx * vx + vz * vz
    if v2 <= 1e-12:
        return math.inf, math.hypot(rx, rz)
    t = -(rx * vx + rz * vz) / v2
    if t < 0.0:
        return t, math.hypot(rx, rz)
    return t, math.hypot(rx + vx * t, rz + vz * t)


def threats(tank: "TankState", shells: Iterable["ShellSeen"], horizon: float = HORIZON,
            margin: float = 0.5) -> list[Threat]:
    """The shells among ``shells`` (the enemies' shells it knows of) that pass within
    the footprint + ``margin`` of the tank in the next ``horizon`` s if it holds its
    present velocity, soonest first."""
    out = []
    reach = tank.vehicle.radius + margin
    for sh in shells:
        if sh.owner == tank.index:
            continue
        t, d = arrival(tank, sh)
        if not (0.0 < t <= horizon) or d > reach:
            continue
        miss = d - half_extent(tank, math.atan2(sh.vz, sh.vx))
        if miss < margin:
            out.append(Threat(sh, t, miss))
    out.sort(key=lambda th: th.arrives)
    return out


def escape(tank: "TankState", shells: Sequence["ShellSeen"], escapes: Sequence[tuple[float, float]] = ESCAPES,
           ) -> tuple[tuple[float, float], float]:
    """The (advance, strafe) that keeps the nearest of ``shells`` farthest outside the
    hull, and that clearance [m] (the worst over the shells).  Ties go to the earlier
    escape in ``escapes`` (holding still first)."""
    if not shells:
        return (0.0, 0.0), math.inf
    last = 0.0
    for sh in shells:
        t, _ = arrival(tank, sh)
        last = max(last, t)
    duration = min(max(last, 0.0) + 0.2, HORIZON + 0.2)
    best, best_c = escapes[0], -math.inf
    safe, safe_c, safe_v = None, -math.inf, -math.inf
    c0, s0 = math.cos(tank.heading), math.sin(tank.heading)
    side = math.copysign(1.0, -tank.vx * s0 + tank.vz * c0)
    for a, s in escapes:
        path = course(tank, a, s, duration)
        c = min(clearance(tank, sh, path) for sh in shells)
        if c > best_c + 1e-9:
            best, best_c = (a, s), c
        if c >= SAFE:
            # the sideways speed it ends with, the way it was going
            (t1, x1, z1), (t2, x2, z2) = path[-2], path[-1]
            v = side * (-(x2 - x1) * s0 + (z2 - z1) * c0) / (t2 - t1)
            if v > safe_v + 1e-9:
                safe, safe_c, safe_v = (a, s), c, v
    if safe is not None:
        return safe, safe_c
    return best, best_c


def moved(shell: "ShellSeen", dt: float) -> "ShellSeen":
    """Where a shell (flying straight) is ``dt`` s later."""
    return replace(shell, x=shell.x + shell.vx * dt, y=shell.y + shell.vy * dt, z=shell.z + shell.vz * dt)


class Evasion:
    """Dodging over time: a shell is noticed ``reaction`` s after it comes into view
    (``visible`` shells passed to :meth:`command`, known by their ``key``); a noticed
    shell that would hit is dodged with :func:`escape`, and the tank stays committed
    to dodging it until it has passed (out of sight, where it is now is worked out
    from where it was seen), so that it does not steer back into its path."""

    def __init__(self, reaction: float = 0.25, margin: float = 0.5) -> None:
        self.reaction = reaction
        self.margin = margin
        self.first_seen: dict[tuple[int, int], float] = {}
        self.committed: dict[tuple[int, int], tuple["ShellSeen", float]] = {}
        self.clearance = math.inf

    def command(self, t: float, tank: "TankState", visible: Sequence["ShellSeen"]) -> tuple[float, float] | None:
        """(advance, strafe) to dodge with at time ``t``, or None: nothing to dodge."""
        vis = {s.key: s for s in visible}
        self.first_seen = {k: t0 for k, t0 in self.first_seen.items() if k in vis}
        for k in vis:
            self.first_seen.setdefault(k, t)
        committed = {}
        for k, (s, ts) in self.committed.items():
            now = vis.get(k) or moved(s, t - ts)
            if arrival(tank, now)[0] > -0.05:
                committed[k] = now
        noticed = [vis[k] for k, t0 in self.first_seen.items() if t - t0 >= self.reaction - 1e-9]
        danger = {th.shell.key: th.shell for th in threats(tank, noticed, margin=self.margin)}
        danger.update(committed)
        if not danger:
            self.committed, self.clearance = {}, math.inf
            return None
        (a, s), c = escape(tank, list(danger.values()))
        self.committed = {k: (sh, t) for k, sh in danger.items()}
        self.clearance = c
        return a, s
