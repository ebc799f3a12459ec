"""Guns and shells.

A shell flies in 3D, under the rules' gravity (``Rules.shell_gravity``: none by
default, 9.81 m/s² in the classic rules), until it has flown ``Rules.shell_range``.  Its (x, z) path is a straight line (gravity only
acts along y), so the first wall on that line is found once, when it is fired, with
the wall index; each step then only compares distances, and no speed can carry a
shell through a wall.  Against tanks, each step's flight is a swept 3D segment tested
against the sphere trees, which again cannot be jumped over.  The flight itself is
integrated exactly for constant acceleration: p += v·dt + ½ g dt², v += g dt.

On a ground (relief, decks) a shell leaves at the hull's pitch and where its flight
first meets the model's triangles is found once, at firing, along chords of its path.
"""

from __future__ import annotations

import math
import random

import numpy as np

from .body import Tank
from .collide import WallSet
from .rules import GRAVITY, Rules


class Shell:
    """A shell in flight.  ``wall_dist`` is the (x, z) distance from the firing point
    to the first wall on its line (inf when none is in range); ``reach`` how far it
    flies in (x, z) before it is spent; ``g`` its downward acceleration."""

    __slots__ = ("owner", "x", "y", "z", "vx", "vy", "vz", "px", "py", "pz",
                 "ox", "oz", "ux", "uz", "wall_dist", "wall", "damage", "alive", "reach", "g", "age", "stop_at")

    def __init__(self, owner: int, x: float, y: float, z: float, vx: float, vy: float, vz: float,
                 damage: float, reach: float = math.inf, g: float = GRAVITY) -> None:
        self.owner = owner
        self.x, self.y, self.z = x, y, z
        self.px, self.py, self.pz = x, y, z          # position before this step
        self.vx, self.vy, self.vz = vx, vy, vz
        self.ox, self.oz = x, z                      # firing point in (x, z)
        h = math.hypot(vx, vz)
        self.ux, self.uz = (vx / h, vz / h) if h > 0 else (0.0, 0.0)
        self.wall_dist = math.inf
        self.wall = -1
        self.damage = damage
        self.alive = True
        self.reach = reach
        self.g = g
        self.age = 0.0                               # seconds in flight
        self.stop_at = math.nan                      # on a ground: when it meets the model [s] (inf: never)

    def flight_time(self) -> float:
        """Seconds until the shell reaches the floor (y = 0) if nothing stops it (inf:
        it flies level or up without gravity)."""
        g = self.g
        if g <= 0.0:
            return math.inf if self.vy >= 0.0 or self.y <= 0.0 else self.y / -self.vy
        return (self.vy + math.sqrt(self.vy * self.vy + 2.0 * g * max(self.y, 0.0))) / g

    def travelled(self, x: float, z: float) -> float:
        return (x - self.ox) * self.ux + (z - self.oz) * self.uz


#: a shell's flight is tested against the model in chords of this duration [s]
CHORD = 0.05
#: and for at most this long
MAX_FLIGHT = 6.0


def fire(tank: Tank, walls: WallSet, rules: Rules | None = None, rng: random.Random | None = None,
         ground=None) -> Shell:
    """A shell leaving ``tank``'s gun now (its spec carries the rules' gun: see
    ``Rules.arm``), thrown off the gun's line by the rules' spread (a Gaussian angle
    drawn from ``rng``).  ``rules`` None: the classic rules.

    It starts above the tank's centre of mass at muzzle height rather than at the
    muzzle, so a tank pressed against a wall cannot shoot through it; the owner is
    never hit by its own shell.  On a ground (``sim.ground.Ground`` with the model) it
    leaves at the hull's pitch from the tank's height, and where its flight first meets
    the model (terrain, decks, ceilings, walls) is found once, now, along chords of its
    parabola: no speed carries it through.
    """
    spec = tank.spec
    v = spec.shell_speed
    c, s = tank.c, tank.s
    g, reach_max = GRAVITY, math.inf
    if rules is not None:
        g, reach_max = rules.shell_gravity, rules.shell_range
        if rules.spread > 0.0 and rng is not None:
            a = rng.gauss(0.0, rules.spread)
            c, s = c * math.cos(a) - s * math.sin(a), s * math.cos(a) + c * math.sin(a)
    mesh = getattr(ground, "mesh", None)     # a flat ground has no model: the walls stop shells
    if mesh is not None:
        cp, sp = math.cos(tank.pitch), math.sin(tank.pitch)
        vx = v * cp * c + tank.vx
        vz = v * cp * s + tank.vz
        shell = Shell(tank.index, tank.x, tank.y + spec.muzzle_local[1], tank.z, vx, v * sp, vz, spec.shell_damage,
                      reach_max, g)
        shell.stop_at = _meets_model(shell, ground.mesh)
        return shell
    vx = v * c + tank.vx
    vz = v * s + tank.vz
    shell = Shell(tank.index, tank.x, tank.y + spec.muzzle_local[1], tank.z, vx, 0.0, vz, spec.shell_damage,
                  reach_max, g)
    reach = min(math.hypot(vx, vz) * shell.flight_time(), reach_max)     # finite: Rules sees to it
    if reach > 0.0 and (shell.ux != 0.0 or shell.uz != 0.0):
        bx, bz = shell.ox + shell.ux * reach, shell.oz + shell.uz * reach
        hit = walls.first_hit(shell.ox, shell.oz, bx, bz)
        if hit is not None:
            shell.wall_dist = hit[0] * reach
            shell.wall = hit[1]
    return shell


#: chords tested together (a shell hits most things within the first few)
CHUNK = 8


def _meets_model(shell: Shell, mesh) -> float:
    """Seconds until the shell's flight first meets the model (inf: never, within
    MAX_FLIGHT or before it falls below the model's lowest point).  The flight is
    tested CHUNK chords at a time, from the muzzle on, so a shell that hits early costs
    little."""
    flight = MAX_FLIGHT
    speed = math.hypot(shell.vx, shell.vz)
    if speed > 0.0 and math.isfinite(shell.reach):
        flight = min(flight, shell.reach / speed + CHORD)   # no further than it is spent
    if shell.g == 0.0:
        # a straight flight: one segment, tested at once
        end = (shell.x + shell.vx * flight, shell.y + shell.vy * flight, shell.z + shell.vz * flight)
        f = mesh.first_hit((shell.x, shell.y, shell.z), end)
        return math.inf if f is None else float(f * flight)
    n = int(math.ceil(flight / CHORD))
    t = np.arange(n + 1) * CHORD
    y = shell.y + shell.vy * t - 0.5 * shell.g * t * t
    below = np.flatnonzero(y < mesh.y_min - 1.0)
    if len(below):
        n = int(below[0])
        t, y = t[:n + 1], y[:n + 1]
    pts = np.column_stack([shell.x + shell.vx * t, y, shell.z + shell.vz * t])
    for k0 in range(0, len(pts) - 1, CHUNK):
        hit = mesh.first_hit_path(pts[k0:k0 + CHUNK + 1])
        if hit is not None:
            k, f = hit
            return float(t[k0 + k] + f * CHORD)
    return math.inf


def fly(shell: Shell, dt: float) -> None:
    """Move a shell through one step (exact under constant gravity)."""
    shell.age += dt
    shell.px, shell.py, shell.pz = shell.x, shell.y, shell.z
    shell.x += shell.vx * dt
    shell.z += shell.vz * dt
    shell.y += shell.vy * dt - 0.5 * shell.g * dt * dt
    shell.vy -= shell.g * dt


def stop_fraction(shell: Shell, dt: float | None = None) -> tuple[float, str]:
    """Where along this step's flight the shell meets a wall or the floor, or is spent
    (its range flown): (fraction in [0, 1], "wall" | "floor" | "ground" | "spent"), or
    (inf, "") when it flies on.  On a ground ``dt``, this step's length, places the
    meeting with the model found at firing."""
    if not math.isnan(shell.stop_at):  # fired on a ground: the model, found at firing
        best, what = math.inf, ""
        if shell.age >= shell.stop_at:
            step = dt if dt else shell.age
            best, what = min(max(1.0 - (shell.age - shell.stop_at) / step, 0.0), 1.0), "ground"
        d0 = shell.travelled(shell.px, shell.pz)
        d1 = shell.travelled(shell.x, shell.z)
        if d1 >= shell.reach and d1 > d0:
            f = max((shell.reach - d0) / (d1 - d0), 0.0)
            if f < best:
                best, what = f, "spent"
        elif shell.age >= MAX_FLIGHT and not what:
            best, what = 1.0, "spent"
        return best, what
    best, what = math.inf, ""
    d0 = shell.travelled(shell.px, shell.pz)
    d1 = shell.travelled(shell.x, shell.z)
    if d1 >= shell.wall_dist and d1 > d0:
        best, what = max((shell.wall_dist - d0) / (d1 - d0), 0.0), "wall"
    if d1 >= shell.reach and d1 > d0 and shell.reach < shell.wall_dist:
        best, what = max((shell.reach - d0) / (d1 - d0), 0.0), "spent"
    if shell.y <= 0.0 and shell.py > shell.y:
        f = shell.py / (shell.py - shell.y)
        if f < best:
            best, what = f, "floor"
    return best, what
