"""A tank's view (the bot API's ``View``) as a fixed-size float32 vector in [-1, 1].

Everything is in the tank's own frame where a direction matters: ``fwd`` along its
heading, ``right`` to its right (f x up), so a policy does not have to learn the
arena's orientation.  The layout (``FIELDS``, 53 numbers) is documented in
docs/env.md; distances are divided by the sense that bounds them (vision range,
hearing radius, ``FEELER`` m), speeds by the vehicle's top speed or shell speed.
"""

from __future__ import annotations

import math

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
    walls = view.map.walls_of(me.level)
    for k, (dc, ds) in enumerate(_FEELER_DIRS):
        fx, fz = c * dc - s * ds, s * dc + c * ds      # the heading turned by 2 pi k / FEELERS
        hit = walls.first_hit(me.x, me.z, me.x + FEELER * fx, me.z + FEELER * fz)
        out[o + k] = 1.0 if hit is None else max(hit[0], 0.0)
    return np.clip(np.asarray(out, dtype=np.float32), -1.0, 1.0)
