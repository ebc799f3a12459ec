"""Particle effects of the 3D view, simulated on the CPU with numpy.

What the match does becomes bursts of particles (:data:`RECIPES`):

* a **shot**: the muzzle flash (one big bright flare for a few hundredths of a second),
  a long cone of flame forward, the muzzle brake's blast to the sides and smoke;
* a **hit**: sparks thrown back towards the shooter, a flash, smoke and a few fragments;
* a **kill**: the explosion: a flash, fire that rises and cools from yellow to red,
  dark smoke that swells and drifts up, debris (some of it glowing) thrown out that
  falls and bounces, sparks, and a ring of dust blown along the ground;
* a shell stopped by a wall or the ground (no event says so: a shell that leaves the
  world without a hit): a puff of dust and a few sparks;
* **dust** behind the tracks of every moving tank (more the faster it goes), and over
  wrecks smoke and, for ``BURN_S`` seconds after the kill, flames dying down.

Each particle has a life, a size and a colour going from their start to their end
values, a drag, a lift (negative: it falls) and ``glow`` (1 adds light, 0 covers what is
behind).  The view draws them as soft camera-facing quads (game/shaders.py), never
wider on screen than a share of the window and faded out near the camera, so no
explosion ever blinds the player.  The particle level (game/quality.py) scales every
burst and caps how many may live at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .quality import PARTICLE_BUDGET, PARTICLE_SHARE

GRAVITY = 9.81
#: floats per particle instance the view uploads: x y z size r g b a glow
INSTANCE = 9
#: the per-particle arrays of :class:`Particles`
FIELDS = ("pos", "vel", "age", "life", "size", "rgba", "glow", "lift", "drag", "floor", "fade")


@dataclass(frozen=True)
class Burst:
    """``count`` particles thrown from a point."""

    count: int
    life: tuple[float, float]
    speed: tuple[float, float]
    spread: float                      # cone half-angle about the direction [rad]; pi: every way
    size: tuple[float, float]          # at birth, at death [m]
    rgba0: tuple[float, float, float, float]
    rgba1: tuple[float, float, float, float]
    glow: float = 0.0
    lift: float = 0.0                  # m/s², up positive (smoke rises, debris falls at -g)
    drag: float = 1.0                  # 1/s
    jitter: float = 0.2                # start positions spread [m]
    up: float = 0.0                    # added upward share of the direction (fire rises)
    fade_in: float = 0.0               # seconds to full opacity (smoke must not hide the flash)


#: a flash's colour: orange-white, a little below full so that overlapping glows stay orange
FLASH = (1.0, 0.78, 0.42, 0.85)
RECIPES: dict[str, tuple[Burst, ...]] = {
    "shot": (
        # a heavy gun: a big flare, a long tongue of flame, the muzzle brake's side blast
        Burst(1, (0.07, 0.09), (0.0, 0.0), 0.0, (2.8, 4.0), FLASH, (1.0, 0.6, 0.2, 0.0), glow=1.0, jitter=0.0),
        Burst(16, (0.1, 0.2), (10.0, 30.0), 0.2, (0.6, 1.2), (1.0, 0.82, 0.35, 0.95), (1.0, 0.3, 0.05, 0.0),
              glow=1.0, drag=6.0, jitter=0.05),
        Burst(10, (0.08, 0.14), (6.0, 14.0), 1.4, (0.5, 0.9), (1.0, 0.75, 0.3, 0.9), (1.0, 0.3, 0.05, 0.0),
              glow=1.0, drag=8.0, jitter=0.05),
        Burst(8, (0.8, 1.4), (1.0, 4.0), 0.9, (0.8, 2.8), (0.55, 0.53, 0.5, 0.4), (0.6, 0.6, 0.6, 0.0),
              lift=0.8, drag=2.0, jitter=0.15, fade_in=0.08),
    ),
    "hit": (
        Burst(1, (0.08, 0.1), (0.0, 0.0), 0.0, (1.2, 2.0), FLASH, (1.0, 0.5, 0.1, 0.0), glow=1.0, jitter=0.0),
        Burst(16, (0.25, 0.55), (6.0, 16.0), 0.9, (0.16, 0.08), (1.0, 0.95, 0.6, 1.0), (1.0, 0.45, 0.1, 0.0),
              glow=1.0, lift=-GRAVITY, drag=0.8, jitter=0.1),
        Burst(4, (0.8, 1.4), (0.5, 2.0), math.pi, (0.8, 2.4), (0.3, 0.29, 0.27, 0.45), (0.45, 0.45, 0.45, 0.0),
              lift=0.7, drag=1.5, jitter=0.3, fade_in=0.15),
        Burst(5, (0.8, 1.3), (3.0, 7.0), 1.0, (0.18, 0.18), (0.15, 0.13, 0.1, 1.0), (0.15, 0.13, 0.1, 0.9),
              lift=-GRAVITY, drag=0.3, jitter=0.1, up=0.6),
    ),
    "explosion": (
        Burst(1, (0.16, 0.2), (0.0, 0.0), 0.0, (3.5, 6.0), FLASH, (1.0, 0.5, 0.1, 0.0), glow=1.0, jitter=0.0),
        Burst(28, (0.5, 1.1), (2.0, 7.0), math.pi, (1.4, 3.2), (1.0, 0.62, 0.18, 0.95), (0.7, 0.12, 0.02, 0.0),
              glow=0.6, lift=3.0, drag=2.2, jitter=0.9, up=1.2),
        Burst(18, (1.8, 3.0), (1.0, 3.5), math.pi, (1.8, 5.0), (0.12, 0.11, 0.1, 0.55), (0.35, 0.34, 0.33, 0.0),
              lift=1.8, drag=1.2, jitter=1.0, up=1.5, fade_in=0.35),
        # debris: hull plates and track links thrown out, falling and bouncing, some still glowing
        Burst(26, (1.4, 2.4), (5.0, 15.0), 1.2, (0.45, 0.35), (0.12, 0.1, 0.08, 1.0), (0.12, 0.1, 0.08, 0.9),
              lift=-GRAVITY, drag=0.2, jitter=0.5, up=0.8),
        Burst(10, (1.0, 1.8), (6.0, 14.0), 1.0, (0.3, 0.2), (1.0, 0.6, 0.2, 1.0), (0.5, 0.12, 0.03, 0.6),
              glow=1.0, lift=-GRAVITY, drag=0.3, jitter=0.4, up=0.9),
        # the blast's dust ring along the ground
        Burst(20, (0.8, 1.4), (6.0, 11.0), 0.25, (1.0, 3.0), (0.5, 0.45, 0.36, 0.5), (0.56, 0.52, 0.45, 0.0),
              lift=0.3, drag=3.0, jitter=0.4, up=-1.0),
        Burst(22, (0.3, 0.8), (8.0, 20.0), math.pi, (0.2, 0.08), (1.0, 0.9, 0.5, 1.0), (1.0, 0.35, 0.05, 0.0),
              glow=1.0, lift=-GRAVITY, drag=0.6, jitter=0.3, up=0.4),
    ),
    "ricochet": (
        Burst(7, (0.15, 0.35), (4.0, 10.0), 1.1, (0.12, 0.06), (1.0, 0.9, 0.6, 1.0), (1.0, 0.5, 0.1, 0.0),
              glow=1.0, lift=-GRAVITY, drag=1.0, jitter=0.05),
        Burst(5, (0.6, 1.1), (0.5, 2.5), 1.2, (0.5, 1.8), (0.5, 0.45, 0.38, 0.5), (0.55, 0.5, 0.45, 0.0),
              lift=0.3, drag=2.0, jitter=0.2),
    ),
    "dust": (
        Burst(1, (0.9, 1.5), (0.2, 0.8), math.pi, (0.5, 2.2), (0.52, 0.46, 0.36, 0.28), (0.58, 0.53, 0.45, 0.0),
              lift=0.25, drag=1.5, jitter=0.3, up=0.3),
    ),
    "wreck": (
        Burst(1, (1.8, 2.8), (0.4, 1.0), 0.5, (1.0, 3.6), (0.1, 0.1, 0.1, 0.45), (0.3, 0.3, 0.3, 0.0),
              lift=1.6, drag=0.8, jitter=0.6, up=1.0),
    ),
    "fire": (
        Burst(1, (0.35, 0.7), (0.5, 1.5), 0.4, (1.2, 0.3), (1.0, 0.7, 0.25, 0.9), (0.9, 0.2, 0.03, 0.0),
              glow=1.0, lift=2.5, drag=1.5, jitter=0.8, up=1.0),
    ),
}
#: dust puffs per second and track at top speed; wreck smoke puffs per second
DUST_RATE = 14.0
WRECK_RATE = 7.0
#: flames a second over a fresh wreck, dying down over BURN_S seconds
FIRE_RATE, BURN_S = 24.0, 8.0


class Particles:
    """Every live particle, in arrays of one row per particle."""

    def __init__(self, level: str = "normal", seed: int = 0) -> None:
        self.level = level
        self.budget = PARTICLE_BUDGET.get(level, 0)
        self.share = PARTICLE_SHARE.get(level, 0.0)
        self.rng = np.random.default_rng(seed)
        n = 0
        self.pos = np.zeros((n, 3))
        self.vel = np.zeros((n, 3))
        self.age = np.zeros(n)
        self.life = np.ones(n)
        self.size = np.zeros((n, 2))
        self.rgba = np.zeros((n, 2, 4))
        self.glow = np.zeros(n)
        self.lift = np.zeros(n)
        self.drag = np.zeros(n)
        self.floor = np.zeros(n)
        self.fade = np.zeros(n)
        self._carry: dict[Any, float] = {}        # fractional particles owed by steady emitters

    def __len__(self) -> int:
        return len(self.age)

    # ------------------------------------------------------------------ emitting
    def emit(self, kind: str, at: Any, direction: Any = (0.0, 1.0, 0.0), velocity: Any = (0.0, 0.0, 0.0),
             floor: float = 0.0, scale: float = 1.0) -> int:
        """Throw one recipe's particles from ``at`` towards ``direction`` (plus
        ``velocity``, the emitter's own).  ``floor``: the height debris bounces on.
        Returns how many were made (fewer at low levels, none past the budget)."""
        made = 0
        for b in RECIPES[kind]:
            made += self._burst(b, at, direction, velocity, floor, scale)
        return made

    def emit_steady(self, key: Any, kind: str, rate: float, dt: float, at: Any, direction: Any = (0.0, 1.0, 0.0),
                    velocity: Any = (0.0, 0.0, 0.0), floor: float = 0.0) -> int:
        """A steady emitter (``rate`` bursts a second; ``key`` keeps its fractions)."""
        owed = self._carry.get(key, 0.0) + rate * dt * self.share
        whole = int(owed)
        self._carry[key] = owed - whole
        made = 0
        for _ in range(whole):
            for b in RECIPES[kind]:
                made += self._burst(b, at, direction, velocity, floor, 1.0, exact=True)
        return made

    def _burst(self, b: Burst, at: Any, direction: Any, velocity: Any, floor: float, scale: float,
               exact: bool = False) -> int:
        k = b.count if exact else int(math.ceil(b.count * self.share)) if b.count > 1 else (1 if self.share else 0)
        k = min(k, max(self.budget - len(self), 0))
        if k <= 0:
            return 0
        rng = self.rng
        d = np.asarray(direction, dtype=np.float64) + np.array([0.0, b.up, 0.0])
        norm = np.linalg.norm(d)
        d = d / norm if norm > 1e-9 else np.array([0.0, 1.0, 0.0])
        dirs = _cone(rng, d, b.spread, k)
        speed = rng.uniform(*b.speed, k)[:, None]
        pos = np.asarray(at, dtype=np.float64) + rng.normal(0.0, b.jitter, (k, 3)) * scale
        pos[:, 1] = np.maximum(pos[:, 1], floor + 0.05)          # nothing starts under the ground
        self.pos = np.concatenate([self.pos, pos])
        self.vel = np.concatenate([self.vel, dirs * speed * scale + np.asarray(velocity, dtype=np.float64)])
        self.age = np.concatenate([self.age, np.zeros(k)])
        self.life = np.concatenate([self.life, rng.uniform(*b.life, k)])
        self.size = np.concatenate([self.size, np.tile(np.array(b.size) * scale, (k, 1)) * rng.uniform(0.8, 1.2, (k, 1))])
        self.rgba = np.concatenate([self.rgba, np.tile(np.array([b.rgba0, b.rgba1]), (k, 1, 1))])
        self.glow = np.concatenate([self.glow, np.full(k, b.glow)])
        self.lift = np.concatenate([self.lift, np.full(k, b.lift)])
        self.drag = np.concatenate([self.drag, np.full(k, b.drag)])
        self.floor = np.concatenate([self.floor, np.full(k, floor)])
        self.fade = np.concatenate([self.fade, np.full(k, b.fade_in)])
        return k

    # ------------------------------------------------------------------ time
    def update(self, dt: float) -> None:
        """Move every particle ``dt`` seconds on; the dead go."""
        if dt <= 0 or not len(self):
            return
        self.age += dt
        keep = self.age < self.life
        if not keep.all():
            for name in FIELDS:
                setattr(self, name, getattr(self, name)[keep])
        self.vel *= np.exp(-self.drag * dt)[:, None]
        self.vel[:, 1] += self.lift * dt
        self.pos += self.vel * dt
        # what falls bounces on the floor, losing most of its speed
        low = (self.pos[:, 1] < self.floor) & (self.lift < 0)
        if low.any():
            self.pos[low, 1] = self.floor[low]
            self.vel[low] *= np.array([0.5, -0.3, 0.5])

    def clear(self) -> None:
        for name in FIELDS:
            a = getattr(self, name)
            setattr(self, name, a[:0])

    def instances(self, eye: Any) -> np.ndarray:
        """(n, INSTANCE) float32 rows ``x y z size r g b a glow``, farthest first."""
        n = len(self)
        if not n:
            return np.zeros((0, INSTANCE), dtype="f4")
        f = np.clip(self.age / self.life, 0.0, 1.0)
        size = self.size[:, 0] + (self.size[:, 1] - self.size[:, 0]) * f
        rgba = self.rgba[:, 0] + (self.rgba[:, 1] - self.rgba[:, 0]) * f[:, None]
        rgba[:, 3] *= np.where(self.fade > 0, np.minimum(self.age / np.maximum(self.fade, 1e-6), 1.0), 1.0)
        order = np.argsort(-np.sum((self.pos - np.asarray(eye, dtype=np.float64)) ** 2, axis=1))
        out = np.empty((n, INSTANCE), dtype="f4")
        out[:, :3] = self.pos
        out[:, 3] = size
        out[:, 4:8] = rgba
        out[:, 8] = self.glow
        return out[order]


def _cone(rng: np.random.Generator, axis: np.ndarray, half_angle: float, k: int) -> np.ndarray:
    """(k, 3) unit vectors spread uniformly over a cone of ``half_angle`` about ``axis``."""
    cos_min = math.cos(min(half_angle, math.pi))
    z = rng.uniform(cos_min, 1.0, k)
    phi = rng.uniform(0.0, 2 * math.pi, k)
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    local = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    # an orthonormal frame with ``axis`` as its third vector
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    return local[:, :1] * u + local[:, 1:2] * v + local[:, 2:3] * axis


class SessionEffects:
    """Keeps a :class:`Particles` in step with a game session: bursts for the
    session's new effects and for shells that stopped, dust behind moving tanks,
    smoke over wrecks.  Also the tracers of the shells in flight."""

    def __init__(self, level: str = "normal", seed: int = 0) -> None:
        self.particles = Particles(level, seed)
        self._seen: set[int] = set()
        self._shells: dict[int, tuple[float, float, float]] = {}
        self._t: float | None = None
        self._died: dict[int, float] = {}        # when each wreck was first seen [s]

    def sync(self, session: Any, floor_y: float = 0.0) -> None:
        """Catch up with ``session`` (call once a frame, before drawing)."""
        p = self.particles
        t = float(session.t)
        dt = 0.0 if self._t is None else t - self._t
        if dt < 0.0 or dt > 1.0:            # a restart or a jump: start clean
            p.clear()
            self._seen.clear()
            self._shells.clear()
            self._died.clear()
            dt = 0.0
        self._t = t
        live = set()
        for e in session.effects:
            live.add(id(e))
            if id(e) in self._seen:
                continue
            self._seen.add(id(e))
            self._start(e, floor_y)
        self._seen &= live
        self._stopped_shells(session, floor_y)
        if dt > 0.0:
            self._tanks(session, dt, floor_y)
            p.update(dt)

    def _start(self, e: Any, floor_y: float) -> None:
        p = self.particles
        heading = getattr(e, "heading", None)
        if e.kind == "flash":
            d = (math.cos(heading), 0.0, math.sin(heading)) if heading is not None else (1.0, 0.0, 0.0)
            p.emit("shot", (e.x, e.y, e.z), d, floor=floor_y)
        elif e.kind == "impact":
            back = getattr(e, "back", None) or (0.0, 1.0, 0.0)
            p.emit("hit", (e.x, e.y, e.z), back, floor=floor_y)
        elif e.kind == "explosion":
            p.emit("explosion", (e.x, e.y, e.z), (0.0, 1.0, 0.0), floor=floor_y)

    def _stopped_shells(self, session: Any, floor_y: float) -> None:
        now = {id(s): (s.x, s.y, s.z) for s in session.world.shells}
        hits = [(e.x, e.z) for e in session.effects if e.kind == "impact" and e.age(session.t) < 0.05]
        for key, (x, y, z) in self._shells.items():
            if key in now:
                continue
            # a shell that hit a tank made a hit effect there; the others met a wall or the ground
            if any((x - hx) ** 2 + (z - hz) ** 2 < 36.0 for hx, hz in hits):
                continue
            self.particles.emit("ricochet", (x, max(y, floor_y + 0.1), z), (0.0, 1.0, 0.0), floor=floor_y)
        self._shells = now

    def _tanks(self, session: Any, dt: float, floor_y: float) -> None:
        p = self.particles
        for t in session.world.tanks:
            y = float(getattr(t, "y", floor_y))
            if not t.alive:
                p.emit_steady(("wreck", t.index), "wreck", WRECK_RATE, dt, (t.x, y + 1.5, t.z), floor=y)
                burning = 1.0 - (float(session.t) - self._died.setdefault(t.index, float(session.t))) / BURN_S
                if burning > 0.0:           # the wreck burns, the flames dying down
                    p.emit_steady(("fire", t.index), "fire", FIRE_RATE * burning, dt,
                                  (t.x, y + 0.6 * t.spec.height, t.z), floor=y)
                continue
            self._died.pop(t.index, None)
            speed = t.speed()
            if speed < 1.0:
                continue
            rate = DUST_RATE * min(speed / max(t.spec.top_speed, 1e-6), 1.5)
            xs = [lx for lx, _ in t.spec.footprint]
            zs = [lz for _, lz in t.spec.footprint]
            rear, half = min(xs), 0.8 * (max(zs) - min(zs)) / 2
            for side in (-1, 1):
                wx, wz = t.to_world(rear, side * half)
                p.emit_steady(("dust", t.index, side), "dust", rate, dt, (wx, y + 0.3, wz),
                              velocity=(0.2 * t.vx, 0.0, 0.2 * t.vz), floor=y)

    @staticmethod
    def tracers(session: Any, alpha: float, eye: Any, length: float = 14.0, width: float = 0.22) -> np.ndarray:
        """(6k, 9) float32 vertices ``x y z  across along  r g b a`` of the shells' tracer
        ribbons (two triangles each), facing the camera at ``eye``."""
        rows = []
        eye = np.asarray(eye, dtype=np.float64)
        for s in session.world.shells:
            head = np.array([s.px + alpha * (s.x - s.px), s.py + alpha * (s.y - s.py), s.pz + alpha * (s.z - s.pz)])
            v = np.array([s.vx, s.vy, s.vz])
            speed = float(np.linalg.norm(v))
            if speed < 1e-6:
                continue
            d = v / speed
            flown = math.hypot(head[0] - s.ox, head[2] - s.oz)
            tail = head - d * min(length, speed * 0.03, flown + 0.5)
            side = np.cross(d, head - eye)
            n = np.linalg.norm(side)
            if n < 1e-9:
                continue
            # close to the camera a tracer thins and fades, judged by its nearest point (a
            # ribbon is long): a shell passing the lens is no bar of light across the view
            ab = head - tail
            k = float(np.clip(np.dot(eye - tail, ab) / max(float(np.dot(ab, ab)), 1e-9), 0.0, 1.0))
            near = float(np.linalg.norm(tail + k * ab - eye))
            side *= min(width, 0.004 * near) / n            # at most a few pixels wide
            fade = min(max((near - 3.0) / 9.0, 0.0), 1.0)
            if fade <= 0.0:
                continue
            colour = (1.0, 0.85, 0.45, fade)
            quad = [(tail - side, -1, 0), (tail + side, 1, 0), (head + side, 1, 1),
                    (tail - side, -1, 0), (head + side, 1, 1), (head - side, -1, 1)]
            rows += [(*pt, a, b, *colour) for pt, a, b in quad]
        return np.array(rows, dtype="f4").reshape(-1, 9)
