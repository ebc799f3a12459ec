"""A tank's view (the bot API's ``View``) as a fixed-size float32 vector in [-1, 1].

Everything is in the tank's own frame where a direction matters: ``fwd`` along its
heading, ``right`` to its right (f x up), so a policy does not have to learn the
arena's orientation.  The layout (``FIELDS``, 53 numbers) is documented in
docs/env.md; distances are divided by the sense that bounds them (vision range,
hearing radius, ``FEELER`` m), speeds by the vehicle's top speed or shell speed.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from ..sim.bots import View

#: enemies in sight described, nearest first
SEEN_SLOTS = 3
#: wall feelers: directions relative to the heading and their reach [m]
FEELERS = 8
FEELER = 30.0
#: a last sighting older than this counts as 1 in the ``age`` field [s]
MEMORY_SCALE = 10.0

_SELF = ("x", "z", "cos_heading", "sin_heading", "vx", "vz", "turn_rate", "hp", "reload", "alive",
         "protected", "time")
_SEEN = ("present", "fwd", "right", "distance", "v_fwd", "v_right")
FIELDS: tuple[str, ...] = (
    tuple(f"me.{f}" for f in _SELF)
    + tuple(f"seen{k}.{f}" for k in range(SEEN_SLOTS) for f in _SEEN)
    + tuple(f"last_seen.{f}" for f in ("present", "fwd", "right", "age"))
    + tuple(f"heard.{f}" for f in ("present", "fwd", "right"))
    + tuple(f"engine.{f}" for f in ("present", "fwd", "right"))
    + tuple(f"shell.{f}" for f in ("present", "fwd", "right", "v_fwd", "v_right"))
    + tuple(f"feeler{k}" for k in range(FEELERS))
)
SIZE = len(FIELDS)
_FEELER_DIRS = [(math.cos(2 * math.pi * k / FEELERS), math.sin(2 * math.pi * k / FEELERS)) for k in range(FEELERS)]


def observe(view: View, seconds: float) -> np.ndarray:
    """(SIZE,) float32 in [-1, 1]: ``view`` as numbers (``seconds``: the episode's length)."""
    me, sn = view.me, view.senses
    veh = me.vehicle
    c, s = math.cos(me.heading), math.sin(me.heading)
    (x0, z0), (x1, z1) = view.map.bounds.tolist()
    top = max(veh.top_speed, 1e-6)
    out = [0.0] * SIZE

    def local(dx: float, dz: float) -> tuple[float, float]:
        return dx * c + dz * s, -dx * s + dz * c      # (fwd, right): right = f x up = (-f_z, f_x)

    out[0:12] = [2 * (me.x - x0) / max(x1 - x0, 1e-9) - 1, 2 * (me.z - z0) / max(z1 - z0, 1e-9) - 1, c, s,
                 me.vx / top, me.vz / top, me.omega / max(veh.turn_rate, 1e-6), me.hp / max(veh.hit_points, 1e-9),
                 me.reload / max(veh.fire_interval, 1e-9), 1.0 if me.alive else 0.0,
                 1.0 if me.protected > 0 else 0.0, view.t / max(seconds, 1e-9)]
    o = 12
    rng = max(sn.vision_range, 1e-6)
    for k in range(SEEN_SLOTS):
        if k < len(view.seen):
            e = view.seen[k]
            f, r = local(e.x - me.x, e.z - me.z)
            vf, vr = local(e.vx, e.vz)
            out[o:o + 6] = [1.0, f / rng, r / rng, e.distance / rng, vf / top, vr / top]
        o += 6
    if view.memory.last_seen:
        last = max(view.memory.last_seen.values(), key=lambda e: (e.t, -e.index))
        f, r = local(last.x - me.x, last.z - me.z)
        out[o:o + 4] = [1.0, f / rng, r / rng, (view.t - last.t) / MEMORY_SCALE]
    o += 4
    hr = max(sn.hearing_radius, 1e-6)
    for group in (view.heard, view.engines):
        if group:
            f, r = local(group[0].x - me.x, group[0].z - me.z)
            out[o:o + 3] = [1.0, f / hr, r / hr]
        o += 3
    if view.shells:
        sh = min(view.shells, key=lambda q: (q.x - me.x) ** 2 + (q.z - me.z) ** 2)
        f, r = local(sh.x - me.x, sh.z - me.z)
        vf, vr = local(sh.vx, sh.vz)
        v = max(veh.shell_speed, 1e-6)
        out[o:o + 5] = [1.0, f / rng, r / rng, vf / v, vr / v]
    o += 5
    out[o:o + FEELERS] = feelers(view.map.walls_of(me.level), me.x, me.z, c, s).tolist()
    return np.clip(np.asarray(out, dtype=np.float32), -1.0, 1.0)


_DIRS = np.array(_FEELER_DIRS)
#: per WallSet, its walls' starts and extents (weak: a finished episode's world goes)
_SEGMENTS: "weakref.WeakKeyDictionary[object, tuple[np.ndarray, np.ndarray]]" = weakref.WeakKeyDictionary()


def feelers(walls: object, x: float, z: float, c: float, s: float) -> np.ndarray:
    """(FEELERS,) fraction of ``FEELER`` m to the first wall of ``walls`` (a
    ``sim.collide.WallSet``) along the heading (c, s) turned by 2 pi k / FEELERS; 1
    when none.  All rays against all walls in one go (arenas have tens of walls: 8
    index walks cost ten times more)."""
    got = _SEGMENTS.get(walls)
    if got is None:
        seg = np.asarray(walls.segments, dtype=np.float64).reshape(-1, 2, 2)   # type: ignore[attr-defined]
        e = seg[:, 1] - seg[:, 0]
        keep = np.hypot(e[:, 0], e[:, 1]) > 1e-9
        got = _SEGMENTS[walls] = (seg[keep, 0], e[keep])
    p, e = got
    dx = FEELER * (c * _DIRS[:, 0] - s * _DIRS[:, 1])          # (F,) ray vectors
    dz = FEELER * (s * _DIRS[:, 0] + c * _DIRS[:, 1])
    wx, wz = p[:, 0] - x, p[:, 1] - z                           # (W,) wall starts from the tank
    denom = dx[:, None] * e[None, :, 1] - dz[:, None] * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (wx[None] * e[None, :, 1] - wz[None] * e[None, :, 0]) / denom        # along the ray
        u = (wx[None] * dz[:, None] - wz[None] * dx[:, None]) / denom            # along the wall
    hit = (denom != 0.0) & (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0)
    return np.where(hit, t, 1.0).min(axis=1, initial=1.0)
