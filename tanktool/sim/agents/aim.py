"""Aiming a gun that is the hull: the intercept (lead) point, and how far a shot fired
now would miss.

A shell leaves at the gun's muzzle speed *plus the shooter's own velocity*, so in the
shooter's moving frame it flies at the muzzle speed along the hull's heading, and
the target moves at the relative velocity v_t - v_s.  The exact intercept is the
time t > 0 with |r + v_rel t| = v_shell t (the smaller root of a quadratic; none when
the target outruns the shell), and the gun must point along r + v_rel t.

``predicted_miss`` is the distance by which a shell fired now (or after ``delay``
seconds of the present turn) passes the target's centre if the target keeps its
velocity: the test to fire on ("fire when the predicted miss is small").  Compare it
with ``dodge.half_extent`` of the target across the shot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Solution:
    """Where to point: ``heading`` [rad] and the flight ``time`` [s] to the intercept,
    ``x, z`` the intercept point (world)."""

    heading: float
    time: float
    x: float
    z: float


def intercept(sx: float, sz: float, svx: float, svz: float, tx: float, tz: float, tvx: float, tvz: float,
              shell_speed: float) -> Solution | None:
    """The exact intercept of a target at (tx, tz) moving at (tvx, tvz) by a shell of
    ``shell_speed`` fired from (sx, sz) by a shooter moving at (svx, svz); None when
    no shell can catch it."""
    rx, rz = tx - sx, tz - sz
    vx, vz = tvx - svx, tvz - svz
    a = vx * vx + vz * vz - shell_speed * shell_speed
    b = 2.0 * (rx * vx + rz * vz)
    c = rx * rx + rz * rz
    if abs(a) < 1e-9:
        if b >= 0.0:
            return None
        t = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            return None
        q = math.sqrt(disc)
        roots = sorted(r for r in ((-b - q) / (2.0 * a), (-b + q) / (2.0 * a)) if r > 0.0)
        if not roots:
            return None
        t = roots[0]
    px, pz = rx + vx * t, rz + vz * t
    return Solution(math.atan2(pz, px), t, sx + svx * t + px, sz + svz * t + pz)


def lead_by_distance(sx: float, sz: float, svx: float, svz: float, tx: float, tz: float, tvx: float, tvz: float,
                     shell_speed: float) -> Solution:
    """BZFlag's robots' lead: the target moved on at the relative velocity for
    distance / shell speed (one step of the exact iteration)."""
    rx, rz = tx - sx, tz - sz
    t = math.hypot(rx, rz) / max(shell_speed, 1e-9)
    px, pz = rx + (tvx - svx) * t, rz + (tvz - svz) * t
    return Solution(math.atan2(pz, px), t, sx + svx * t + px, sz + svz * t + pz)


def predicted_miss(sx: float, sz: float, svx: float, svz: float, heading: float, tx: float, tz: float,
                   tvx: float, tvz: float, shell_speed: float, delay: float = 0.0, omega: float = 0.0) -> float:
    """How close [m] a shell fired along ``heading`` after ``delay`` s (the hull turning
    at ``omega`` meanwhile, both tanks keeping their velocities) passes the target's
    centre; inf when it flies away from it."""
    h = heading + omega * delay
    sx, sz = sx + svx * delay, sz + svz * delay
    tx, tz = tx + tvx * delay, tz + tvz * delay
    # in the target's frame the shell moves at w from the muzzle
    wx = shell_speed * math.cos(h) + svx - tvx
    wz = shell_speed * math.sin(h) + svz - tvz
    rx, rz = tx - sx, tz - sz
    w = math.hypot(wx, wz)
    if w <= 1e-9:
        return math.inf
    along = (rx * wx + rz * wz) / w
    if along <= 0.0:
        return math.inf
    return abs(rx * wz - rz * wx) / w


def height_miss(shooter_y: float, pitch: float, shell_speed: float, gravity: float, distance: float,
                target_y: float, target_height: float) -> float:
    """How far [m] above or below a target's body (its base ``target_y`` up to
    ``target_height`` over it) a shell leaving at height ``shooter_y`` with the hull's
    ``pitch`` passes, ``distance`` m away in (x, z); 0 when it passes through the body's
    height.  The gun is the hull: on a slope it points up or down the slope, and a
    target on level ground 30 m away is missed by 5 m from a 10 degree ramp."""
    cp = math.cos(pitch)
    if shell_speed <= 0.0 or cp <= 1e-6:
        return math.inf
    tau = distance / (shell_speed * cp)
    y = shooter_y + shell_speed * math.sin(pitch) * tau - 0.5 * gravity * tau * tau
    return max(target_y - y, y - (target_y + target_height), 0.0)
