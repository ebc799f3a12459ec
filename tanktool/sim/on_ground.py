"""No tank stands where the ground has no level (issue 25).

A spawn point in a hole of the surface, a tank placed by hand off every level, one a
push left where no node is: :func:`put_back` moves it onto the nearest node of the
ground (in the (x, z) plane, a node nearer its height first among equals), so
``Ground.locate`` finds its level and the height under it is the surface's, never
the 0.0 a ground answers where it has none.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .rules import GRAVITY

#: metres of height difference that weigh as one metre across, choosing the node
HEIGHT_WEIGHT = 0.5
#: a tank on a slope not driven uphill along its length (or across it), with less than
#: this of the command that way, slower than HOLD_SPEED that way [m/s], is held there by
#: its tracks (a parked tank's brake; across, the tracks' grip) ...
HOLD_DRIVE = 0.3
HOLD_SPEED = 0.5
#: ... on slopes up to this gradient (rise per metre: 35 degrees)
HOLD_GRADE = 0.7


def slope_pull(t: Any, m: float, advance: float, strafe: float, vf: float, vr: float) -> tuple[float, float]:
    """The pull (x, z) of gravity along the slope on a tank of mass ``m`` tilted
    ``t.pitch``, ``t.roll``: on a plane of gradient G, g G / (1 + |G|^2) downhill
    (g sin(theta) cos(theta)); but for the part along its length when it is driven
    that way with less than ``HOLD_DRIVE`` (``advance``; a pilot braking to a stop
    commands a little), not crawling uphill, and moves slower than ``HOLD_SPEED`` that way
    (``vf``), and the same across it (``strafe``, ``vr``): the tracks hold those.
    Without it a tank stopped on a ramp's 18 degrees crept sideways at 0.36 m/s (the
    grip against the pull) and rolled back down it: parked at the gen-bridge's ramp
    top, it was at the ramp's side in 10 s and tipped over it; the camper rolled off
    the hill it held (the pilot's braking, -0.3 of its speed, a third of the pull)."""
    c, sn = t.c, t.s
    gf, gr = math.tan(t.pitch), -math.tan(t.roll)   # rise along forward, along right
    gx, gz = gf * c - gr * sn, gf * sn + gr * c
    k = -m * GRAVITY / (1.0 + gx * gx + gz * gz)
    if gx * gx + gz * gz <= HOLD_GRADE * HOLD_GRADE:
        # a little of the command uphill, from rest or on the way it goes, is a crawl up
        # the slope (not held: 0.29 of it would climb the 18 degrees it cannot climb);
        # against the way it goes, a brake
        along = abs(advance) < HOLD_DRIVE and abs(vf) < HOLD_SPEED and not (advance * gf > 0.0 <= advance * vf)
        across = abs(strafe) < HOLD_DRIVE and abs(vr) < HOLD_SPEED and not (strafe * gr > 0.0 <= strafe * vr)
        if along or across:
            gf, gr = (0.0 if along else gf), (0.0 if across else gr)
            gx, gz = gf * c - gr * sn, gf * sn + gr * c
    return k * gx, k * gz


def _nodes(ground: Any) -> tuple[np.ndarray, ...]:
    """(level, x, z, y) of every node of the ground, computed once per ground."""
    cached = getattr(ground, "_node_list", None)
    if cached is None:
        ll, ii, jj = np.nonzero(np.isfinite(np.asarray(ground.h)))
        xs = ground.ox + (jj + 0.5) * ground.cell
        zs = ground.oz + (ii + 0.5) * ground.cell
        cached = (ll, xs, zs, np.asarray(ground.h)[ll, ii, jj])
        ground._node_list = cached
    return cached


def nearest_node(ground: Any, x: float, z: float, y: float | None = None) -> tuple[int, float, float] | None:
    """(level, x, z) of the node of ``ground`` nearest (x, z) (and height ``y``), or
    None when the ground has no node at all."""
    ll, xs, zs, ys = _nodes(ground)
    if len(ll) == 0:
        return None
    d = (xs - x) ** 2 + (zs - z) ** 2
    if y is not None:
        d = d + (HEIGHT_WEIGHT * (ys - y)) ** 2
    k = int(np.argmin(d))
    return int(ll[k]), float(xs[k]), float(zs[k])


def put_back(ground: Any, t: Any, y: float | None = None) -> bool:
    """Move tank ``t`` onto the nearest node when no level of ``ground`` lies under it
    (within a cell); returns whether it moved."""
    if ground.locate(t.x, t.z) >= 0 or ground.near_level(t.x, t.z, t.y if y is None else y) >= 0:
        return False
    node = nearest_node(ground, t.x, t.z, y)
    if node is None:
        return False
    t.level, t.x, t.z = node
    t.vx = t.vz = 0.0
    return True
