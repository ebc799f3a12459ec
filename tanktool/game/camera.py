"""The chase and first-person cameras: where the eye is and what it looks at.

The chase camera sits behind and above the followed tank **along its slope** (the
hull's pitch tilts the offset, so on a hillside it looks up or down the hill with the
tank, not into the ground or over it), and keeps the tank in view:

- **collision with the arena**: the lines from over the turret and from the hull's
  middle to the eye are tested against the arena's own triangles (the model the game
  draws, as a ``sim.ground.MeshIndex``); when something is in the way (a hillside, a
  wall, a roof) or the eye would leave the arena, the camera first **swings** (up over
  it, or round to a side with room) and only then **pulls in**;
- **clearance**: the eye stays ``CLEARANCE`` above the surface under it;
- **smoothing**: the eye's heading, pitch, swing and pull-in follow with short time
  constants (the view does not jolt when the hull bumps); it pulls in at once (a wall
  must never hide the tank) and lets out slowly (no swinging near walls).

First person sits over the turret, tilted with the hull, and looks along it, its
heading and pitch smoothed the same way; a roof over the tank or a wall at its nose pulls
the eye in towards the hull's middle (never into the arena).  Both shake for
a moment when the tank fires, is hit, or something blows up near by (:func:`shake`).  The pose is a
pure function of the session and the smoothing state: tests run it without OpenGL.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: behind and above the tank, and the look-ahead, in tank radii (at least 1 m each)
BACK, UP, AHEAD = 4.5, 2.2, 2.5
#: the eye stays this far from the arena's surfaces [m]: the chase camera's, first person's
#: (the near plane is 0.3 m: a surface closer than that would be cut open)
CLEARANCE, FP_CLEARANCE = 0.6, 0.35
#: time constants of the smoothing [s]: heading and pitch, the swing, letting the eye out
TURN_S, SWING_S, OUT_S = 0.12, 0.25, 0.6
#: the camera's pitch follows the hull's this much (the rest stays level: the horizon reads)
PITCH_SHARE = 0.7
#: the shake's strength [m] when the followed tank fires, is hit, or something blows up
#: (the followed tank itself, or within SHAKE_REACH metres), and how long it lasts [s]
SHAKE = {"flash": 0.08, "impact": 0.3, "explosion": 0.45}
SHAKE_REACH, SHAKE_S = 25.0, 0.4
#: swings tried when the way behind is not free: (round the tank [rad], up [rad]), and
#: what each costs against the room it wins (the plain chase view is preferred)
YAWS = (0.0, 0.7, -0.7, 1.4, -1.4, 2.1, -2.1)
LIFTS = (0.0, 0.3, 0.6, 0.9)
YAW_COST, LIFT_COST = 0.12, 0.15
#: a view pulled in to this share of the full distance loses nothing for it: the plain
#: chase view closer in, looking ahead over the hull, beats swinging up (at the spawn
#: points by a wall the highest swing looked straight down on the hull from 17 m)
ROOM_ENOUGH = 0.4
#: the swings are searched at most this often [s] (a few dozen segment queries)
SEARCH_S = 0.1
#: swung all the way up (a wall right behind, as at many spawn points) the camera still
#: looks this share of the way ahead: looking straight down at the hull, the view showed
#: only ground, and beyond the wall behind the void outside the arena
LOOK_LIFTED = 0.45


def arena_mesh(model: Any) -> Any:
    """The arena model's triangles as a ``sim.ground.MeshIndex`` (segment queries)."""
    from ..sim.ground import MeshIndex

    tri = [b.vertices[:, :3].astype(np.float64) for b in model.batches if len(b.vertices)]
    if not tri:
        return None
    v = np.concatenate(tri)
    return MeshIndex(v, np.arange(len(v), dtype=np.int64).reshape(-1, 3))


@dataclass
class _Eased:
    """The smoothing state: when, the eye's heading and pitch, its swing round and up
    the tank [rad], its pull-in (1: all the way out), and the tank it follows."""

    t: float
    heading: float
    pitch: float
    yaw: float
    lift: float
    pull: float
    tank: int
    at: tuple[float, float]
    #: the swing being eased to, when it was last searched for, the last frame's length
    goal: tuple[float, float] = (0.0, 0.0)
    searched: float = -math.inf
    dt: float = 0.0


class Camera:
    """Chase and first-person poses for one renderer (``mesh``: the arena's triangles,
    or None: no collision)."""

    def __init__(self, mesh: Any = None) -> None:
        self.mesh = mesh
        self._s: _Eased | None = None

    def reset(self) -> None:
        """Forget the smoothing (a new mode, another tank)."""
        self._s = None

    def pose(self, session: Any, alpha: float, mode: str, floor_y: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """(eye, target) of ``mode`` ("chase" or "first-person") for the followed tank."""
        from .session import pose3d

        t = session.focus_tank()
        x, y, z, h, pitch, _ = pose3d(session, t.index, alpha)
        if not hasattr(t, "y"):
            y = floor_y
        now = float(session.t) + alpha * float(session.dt)
        e = self._ease(now, t.index, h, pitch, (x, z))
        p = np.array([x, y, z])
        jolt = shake(session, t.index, now)
        if mode == "first-person":
            return self._first_person(t, p, e, jolt)
        eye, target = self._chase(session, t, p, e)
        return eye + jolt, target + 0.5 * jolt

    # ------------------------------------------------------------------ first person
    def _first_person(self, t: Any, p: np.ndarray, e: _Eased, jolt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The eye over the turret, tilted with the hull (along its slope's normal), pulled
        in towards the hull's middle before it would touch the arena (a roof over it, a
        wall at its nose); it looks along the hull, a little down."""
        c, s_ = math.cos(e.heading), math.sin(e.heading)
        cp, sp = math.cos(e.pitch), math.sin(e.pitch)
        f = np.array([c * cp, sp, s_ * cp])                  # along the hull
        up = np.array([-c * sp, cp, -s_ * sp])               # the hull's up
        centre = p + np.array([0.0, 0.6 * t.spec.height, 0.0])
        want = p + up * (t.spec.height + 0.4) + f * 0.3 * max(t.spec.radius, 1.0) + jolt
        eye = centre + self._room(centre, want, FP_CLEARANCE) * (want - centre)
        return eye, eye + f * 10.0 + np.array([0.0, -0.6, 0.0]) + 2.0 * jolt

    # ------------------------------------------------------------------ chase
    def _chase(self, session: Any, t: Any, p: np.ndarray, e: _Eased) -> tuple[np.ndarray, np.ndarray]:
        size = max(t.spec.radius, 1.0)
        reach = math.hypot(BACK, UP) * size
        pivot = p + np.array([0.0, max(t.spec.height, 1.0) + 0.3, 0.0])         # over the turret
        centre = p + np.array([0.0, 0.6 * t.spec.height, 0.0])
        bounds = np.asarray(session.world.bounds, dtype=np.float64)

        def free(yaw: float, lift: float) -> tuple[float, np.ndarray]:
            want = _offset(p, e.heading + yaw, e.pitch, reach, lift)
            return self._free(pivot, centre, bounds, want), want

        plain, plain_eye = free(0.0, 0.0)
        if plain >= 0.999:
            e.goal = (0.0, 0.0)
        elif e.t >= e.searched + SEARCH_S:
            # the swing that leaves the most room for what it costs (the plain view first)
            e.searched = e.t
            best = (-math.inf, 0.0, 0.0)
            for yaw in YAWS:
                for lift in LIFTS:
                    room = plain if yaw == lift == 0.0 else free(yaw, lift)[0]
                    score = min(room / ROOM_ENOUGH, 1.0) - YAW_COST * abs(yaw) - LIFT_COST * lift
                    if score > best[0] + 0.02:
                        best = (score, yaw, lift)
            e.goal = best[1:]
        # swing towards the goal; the pull-in keeps the tank seen on the way
        a = 1.0 - math.exp(-e.dt / SWING_S) if e.dt > 0.0 else 1.0      # a fresh start: at once
        e.yaw += a * (e.goal[0] - e.yaw)
        e.lift += a * (e.goal[1] - e.lift)
        if abs(e.yaw) < 1e-3 and abs(e.lift) < 1e-3:
            e.yaw = e.lift = 0.0
            k, want = plain, plain_eye            # the plain view, already tested
        else:
            k, want = free(e.yaw, e.lift)
        k = min(k, e.pull)
        e.pull = k
        eye = self._clear(pivot + k * (want - pivot))
        # pulled in close or swung high, look at the tank itself more than ahead of it
        heading = e.heading + e.yaw
        f = np.array([math.cos(heading), 0.0, math.sin(heading)])
        ahead = p + f * AHEAD * size + np.array([0.0, 1.0, 0.0])
        w = k * k * (LOOK_LIFTED + (1.0 - LOOK_LIFTED) * max(1.0 - e.lift / LIFTS[-1], 0.0) ** 2) * max(math.cos(e.yaw), 0.0)
        return eye, centre + w * (ahead - centre)

    def _free(self, pivot: np.ndarray, centre: np.ndarray, bounds: np.ndarray, want: np.ndarray) -> float:
        """How far (0..1) from the pivot towards ``want`` the eye may go: the arena lets it,
        it still sees the hull's middle, and it stays over the arena."""
        return min(self._room(pivot, want), self._room(centre, want), _inside(bounds, pivot, want))

    def _ease(self, now: float, tank: int, heading: float, pitch: float, at: tuple[float, float]) -> _Eased:
        """The smoothing state moved on to ``now``: heading and pitch eased towards the
        tank's, the pull-in let out (``OUT_S``); the chase pulls in at once when the arena
        asks for it."""
        e = self._s
        if e is None or e.tank != tank or now < e.t or now - e.t > 1.0 or math.dist(at, e.at) > 5.0:
            self._s = _Eased(now, heading, pitch, 0.0, 0.0, 1.0, tank, at)      # a respawn is a jump
            return self._s
        e.at = at
        dt = e.dt = now - e.t
        a = 1.0 - math.exp(-dt / TURN_S)
        e.t = now
        e.heading += a * math.remainder(heading - e.heading, 2.0 * math.pi)
        e.pitch += a * (pitch - e.pitch)
        e.pull += (1.0 - math.exp(-dt / OUT_S)) * (1.0 - e.pull)
        return e

    def _room(self, pivot: np.ndarray, want: np.ndarray, clearance: float = CLEARANCE) -> float:
        """How far (0..1) from the pivot towards the wanted eye the arena lets it go, the
        eye ``clearance`` short of what is in the way."""
        if self.mesh is None:
            return 1.0
        d = float(np.linalg.norm(want - pivot))
        if d < 1e-9:
            return 1.0
        # reach past the eye by the clearance: the eye must not touch what is behind it
        beyond = pivot + (want - pivot) * (1.0 + clearance / d)
        hit = self.mesh.first_hit(tuple(pivot), tuple(beyond))
        if hit is None:
            return 1.0
        return max(hit * (1.0 + clearance / d) - clearance / d, 0.08 if clearance >= CLEARANCE else 0.0)

    def _clear(self, eye: np.ndarray) -> np.ndarray:
        """Lift the eye to ``CLEARANCE`` over the surface right under it."""
        if self.mesh is None:
            return eye
        below = eye - np.array([0.0, CLEARANCE, 0.0])
        hit = self.mesh.first_hit(tuple(eye + np.array([0.0, 0.05, 0.0])), tuple(below))
        if hit is None:
            return eye
        ground = eye[1] + 0.05 - hit * (CLEARANCE + 0.05)
        return np.array([eye[0], ground + CLEARANCE, eye[2]])


def shake(session: Any, tank: int, now: float) -> np.ndarray:
    """The camera's jolt [m] at ``now``: a short shake when the followed tank fires
    (``SHAKE["flash"]``), is hit, or something blows up near by (less the farther),
    fading over ``SHAKE_S``; a fixed sum of sines, so a replay shakes the same."""
    amp = 0.0
    me = session.world.tanks[tank] if 0 <= tank < len(session.world.tanks) else None
    for fx in getattr(session, "effects", ()):
        age = (now - fx.t0) / SHAKE_S
        if not 0.0 <= age < 1.0:
            continue
        if fx.kind == "explosion" and me is not None:
            near = max(1.0 - math.hypot(fx.x - me.x, fx.z - me.z) / SHAKE_REACH, 0.0)
            a = SHAKE["explosion"] * (1.0 if fx.tank == tank else near)
        elif fx.tank == tank:
            a = SHAKE.get(fx.kind, 0.0)
        else:
            continue
        amp = max(amp, a * (1.0 - age) ** 2)
    if amp <= 0.0:
        return np.zeros(3)
    w = 2.0 * math.pi * now
    return amp * np.array([math.sin(9.0 * w), 0.8 * math.sin(13.0 * w + 1.0), math.sin(11.0 * w + 2.0)])


def _offset(p: np.ndarray, heading: float, pitch: float, reach: float, lift: float) -> np.ndarray:
    """The chase eye ``reach`` from the tank at ``p``: behind it along ``heading`` and the
    slope (``pitch``, a share ``PITCH_SHARE`` of it), at the chase elevation plus ``lift``."""
    cp, sp = math.cos(pitch * PITCH_SHARE), math.sin(pitch * PITCH_SHARE)
    c, s = math.cos(heading), math.sin(heading)
    f = np.array([c * cp, sp, s * cp])                   # along the slope
    up = np.array([-c * sp, cp, -s * sp])                # the slope's normal
    a = math.atan2(UP, BACK) + lift
    return p - f * reach * math.cos(a) + up * reach * math.sin(a)


def _inside(bounds: np.ndarray, pivot: np.ndarray, want: np.ndarray, margin: float = 0.5) -> float:
    """How far (0..1) from the pivot towards ``want`` the eye stays over the arena
    (``bounds`` ((x0, z0), (x1, z1)), ``margin`` inside): outside it nothing is drawn."""
    k = 1.0
    for axis, j in ((0, 0), (2, 1)):
        lo, hi = bounds[0, j] + margin, bounds[1, j] - margin
        d = want[axis] - pivot[axis]
        if want[axis] > hi and d > 1e-9:
            k = min(k, (hi - pivot[axis]) / d)
        elif want[axis] < lo and d < -1e-9:
            k = min(k, (lo - pivot[axis]) / d)
    return max(k, 0.0)
