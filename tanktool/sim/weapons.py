"""Guns and shells.

A shell flies in 3D, under the rules' gravity (``Rules.shell_gravity``: none by
default, 9.81 m/s² in the classic rules), until it has flown ``Rules.shell_range``.  Its (x, z) path is a straight line (gravity only
acts along y), so the first wall on that line is found once, when it is fired, with
the wall index; each step then only compares distances, and no speed can carry a
shell through a wall.  Against tanks, each step's flight is a swept 3D segment tested
against the sphere trees, which again cannot be jumped over.  The flight itself is
integrated exactly for constant acceleration: p += v·dt + ½ g dt², v += g dt.
"""

from __future__ import annotations

import math
import random

from .body import Tank
from .collide import WallSet
from .rules import GRAVITY, Rules


class Shell:
    """A shell in flight.  ``wall_dist`` is the (x, z) distance from the firing point
    to the first wall on its line (inf when none is in range); ``reach`` how far it
    flies in (x, z) before it is spent; ``g`` its downward acceleration."""

    __slots__ = ("owner", "x", "y", "z", "vx", "vy", "vz", "px", "py", "pz",
                 "ox", "oz", "ux", "uz", "wall_dist", "wall", "damage", "alive", "reach", "g")

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

    def flight_time(self) -> float:
        """Seconds until the shell reaches the floor (y = 0) if nothing stops it (inf:
        it flies level or up without gravity)."""
        g = self.g
        if g <= 0.0:
            return math.inf if self.vy >= 0.0 or self.y <= 0.0 else self.y / -self.vy
        return (self.vy + math.sqrt(self.vy * self.vy + 2.0 * g * max(self.y, 0.0))) / g

    def travelled(self, x: float, z: float) -> float:
        return (x - self.ox) * self.ux + (z - self.oz) * self.uz


def fire(tank: Tank, walls: WallSet, rules: Rules | None = None, rng: random.Random | None = None) -> Shell:
    """A shell leaving ``tank``'s gun now (its spec carries the rules' gun: see
    ``Rules.arm``), thrown off the gun's line by the rules' spread (a Gaussian angle
    drawn from ``rng``).  ``rules`` None: the classic rules.

    It starts above the tank's centre of mass at muzzle height rather than at the
    muzzle, so a tank pressed against a wall cannot shoot through it; the owner is
    never hit by its own shell.
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
    vx = v * c + tank.vx
    vz = v * s + tank.vz
    shell = Shell(tank.index, tank.x, spec.muzzle_local[1], tank.z, vx, 0.0, vz, spec.shell_damage,
                  reach_max, g)
    reach = min(math.hypot(vx, vz) * shell.flight_time(), reach_max)     # finite: Rules sees to it
    if reach > 0.0 and (shell.ux != 0.0 or shell.uz != 0.0):
        bx, bz = shell.ox + shell.ux * reach, shell.oz + shell.uz * reach
        hit = walls.first_hit(shell.ox, shell.oz, bx, bz)
        if hit is not None:
            shell.wall_dist = hit[0] * reach
            shell.wall = hit[1]
    return shell


def fly(shell: Shell, dt: float) -> None:
    """Move a shell through one step (exact under constant gravity)."""
    shell.px, shell.py, shell.pz = shell.x, shell.y, shell.z
    shell.x += shell.vx * dt
    shell.z += shell.vz * dt
    shell.y += shell.vy * dt - 0.5 * shell.g * dt * dt
    shell.vy -= shell.g * dt


def stop_fraction(shell: Shell) -> tuple[float, str]:
    """Where along this step's flight the shell meets a wall or the floor, or is spent
    (its range flown): (fraction in [0, 1], "wall" | "floor" | "spent"), or (inf, "")
    when it flies on."""
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
