"""Driving a tank along a path without hitting walls: the agents' pilot.

``Pilot`` turns wanted speeds into ``Command`` values (a speed controller with
braking, capped by wall feelers, pushed off walls that are too close), follows a
path by pure pursuit braking for its bends, and backs out when it is stuck.  The
computer agent (``agent.Agent``) and the yardstick robots (``robots``) drive with
it, so that what tells them apart is what they decide, not how they steer.  It reads
only the bot API's view (``sim.bots.View``: the tank's own state and the static map).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..commands import Command
from .fuzzy import PREDICT, AttackController
from .perception import wrap

if TYPE_CHECKING:  # pragma: no cover
    from ..bots import TankState, View

#: corners: braking at this fraction of the engine's deceleration, and up to this much
#: faster than 3 m/s through a bend gentler than a right angle [m/s]
CORNER_BRAKE = 0.8
CORNER_FAST = 6.0


class Pilot:
    """Steering, speed control, wall feelers and stuck recovery (a mixin for bots:
    ``unstick`` draws from ``view.rng``).  Subclasses say whether they are on a path
    (``_on_path``) and drop their plans when stuck (``_replan``)."""

    #: stuck: pushing and moved less than this in a second [m]
    STUCK_MOVE = 0.5

    def __init__(self) -> None:
        self.progress_at = (0.0, math.nan, math.nan)
        self.reverse_until = -math.inf
        self.reverse_turn = 1.0

    def _on_path(self) -> bool:
        return False

    def _replan(self) -> None:
        """Forget the paths being followed (stuck: plan afresh from here)."""

    def follow(self, view: "View", points: list[tuple[float, float]], speed: float,
               lookahead: float, corner: tuple[float, float] | None = None, stop: bool = False) -> Command:
        """Pure pursuit of the first point at least ``lookahead`` away (or the last),
        at up to ``speed`` x top speed, slowing to turn and for ``corner`` (the next
        waypoint where the path bends); ``stop``: braking to stand at the last point."""
        tank = view.me
        if not points:
            return self.drive(view, 0.0, 0.0, 0.0)
        x, z = tank.x, tank.z
        tx, tz = points[-1]
        for p in points:
            if math.hypot(p[0] - x, p[1] - z) >= lookahead:
                tx, tz = p
                break
        err = wrap(math.atan2(tz - z, tx - x) - tank.heading)
        rotate = self.turn(tank, err)
        top = tank.vehicle.top_speed
        # turn first, then drive: full speed only when pointing the right way
        v = speed * top * max(0.0, 1.0 - abs(err) / 1.2)
        if corner is not None:
            # the speed to take the bend at: 3 m/s for a right angle or sharper, more
            # for a gentler one; braking at CORNER_BRAKE of the engine's deceleration
            brake = CORNER_BRAKE * tank.vehicle.engine_force / tank.vehicle.mass
            bend = math.pi / 2
            k = points.index(corner) if corner in points else -1
            if 0 <= k < len(points) - 1:
                nx, nz = points[k + 1]
                bend = abs(wrap(math.atan2(nz - corner[1], nx - corner[0]) - math.atan2(corner[1] - z, corner[0] - x)))
            vc = 3.0 + CORNER_FAST * max(0.0, 1.0 - bend / (math.pi / 2))
            v = min(v, vc + math.sqrt(2.0 * brake * math.hypot(corner[0] - x, corner[1] - z)))
        if stop:
            # planned at half the corner braking: the speed controller lags the wish
            brake = 0.5 * CORNER_BRAKE * tank.vehicle.engine_force / tank.vehicle.mass
            v = min(v, math.sqrt(2.0 * brake * math.hypot(points[-1][0] - x, points[-1][1] - z)))
        return self.drive(view, v, 0.0, rotate)

    def approach(self, view: "View", points: list[tuple[float, float]], face: tuple[float, float],
                 speed: float, lookahead: float = 4.0) -> Command:
        """Along ``points`` at up to ``speed`` [m/s] with the hull (and gun) turned to
        ``face``: the way along the path split into forward and sideways moves (slower
        sideways: the strafe is half the engine's), braking to stand at the end."""
        tank = view.me
        x, z = tank.x, tank.z
        rotate = self.turn(tank, wrap(math.atan2(face[1] - z, face[0] - x) - tank.heading))
        if not points:
            return self.drive(view, 0.0, 0.0, rotate)
        tx, tz = points[-1]
        for p in points:
            if math.hypot(p[0] - x, p[1] - z) >= lookahead:
                tx, tz = p
                break
        d = math.hypot(tx - x, tz - z)
        if d < 1e-6:
            return self.drive(view, 0.0, 0.0, rotate)
        end = math.hypot(points[-1][0] - x, points[-1][1] - z)
        brake = 0.5 * tank.vehicle.strafe_force / tank.vehicle.mass
        v = min(speed, math.sqrt(2.0 * brake * end))
        ux, uz = (tx - x) / d * v, (tz - z) / d * v
        return self.drive(view, ux * tank.c + uz * tank.s, -ux * tank.s + uz * tank.c, rotate)

    def turn(self, tank: "TankState", err: float) -> float:
        """The turn command for a heading error, read where the gun will point
        ``PREDICT`` s from now (the fuzzy turn rules)."""
        return AttackController.turn(err - PREDICT * tank.omega)

    def free(self, view: "View", angle: float, length: float, offsets: tuple[float, ...]) -> float:
        """Free distance along ``angle`` from points beside the centre, up to ``length``."""
        tank = view.me
        c, s = math.cos(angle), math.sin(angle)
        best = length
        for o in offsets:
            ox, oz = tank.x - s * o, tank.z + c * o
            hit = view.map.walls_of(tank.level).first_hit(ox, oz, ox + c * length, oz + s * length)
            if hit is not None:
                best = min(best, hit[0] * length)
        return best

    def drive(self, view: "View", forward: float, lateral: float, rotate: float,
              fire: bool = False) -> Command:
        """Commands that reach a wanted forward and sideways speed [m/s] (+ = right).

        Tracks coast far on their own (the rolling drag is weak), so speed is
        controlled, braking included, and capped by the walls: the speed from which
        the tank can still stop, at 60 % of its engine's deceleration, before its
        centre comes within footprint radius + 1 m of a wall.  Feelers are rays from
        the centre and beside it, along the way the tank is going.
        """
        tank = view.me
        spec = tank.vehicle
        c, s = tank.c, tank.s
        vf = tank.vx * c + tank.vz * s
        vr = -tank.vx * s + tank.vz * c
        bx0, bz0, bx1, bz1 = spec.box
        half = 0.5 * (bz1 - bz0)
        length = 0.5 * (bx1 - bx0)
        if abs(forward) > 0.05:
            brake = 0.8 * spec.engine_force / spec.mass
            stop = (bx1 if forward > 0 else -bx0) + 1.0
            reach = stop + forward * forward / (2.0 * brake) + 1.0
            angle = tank.heading if forward > 0 else tank.heading + math.pi
            free = self.free(view, angle, reach, (0.0, half, -half))
            forward = math.copysign(min(abs(forward), math.sqrt(2.0 * brake * max(free - stop, 0.0))), forward)
        if abs(lateral) > 0.05:
            # a strafe stops on the tracks' grip (a slide decays at ``grip`` per second:
            # it covers speed / grip more), not on the strafe force: half of that rate
            stop = spec.radius + 1.0
            angle = tank.heading + math.copysign(math.pi / 2, lateral)
            free = self.free(view, angle, stop + 10.0, (0.0, 0.8 * length, -0.8 * length))
            lateral = math.copysign(min(abs(lateral), 0.5 * spec.grip * max(free - stop, 0.0)), lateral)
        # a wall closer than the footprint radius + 1.5 m pushes the tank away: turning
        # in place sweeps the whole footprint circle, and attack moves go anywhere
        push = spec.radius + 1.5
        px = pz = 0.0
        walls = view.map.walls_of(tank.level)
        for k in walls.near(tank.x, tank.z, push):
            w = walls.walls[k]
            ax, az, ex, ez, l2, _ = w  # type: ignore[misc]
            u = min(max(((tank.x - ax) * ex + (tank.z - az) * ez) / l2, 0.0), 1.0)
            dx, dz = tank.x - (ax + u * ex), tank.z - (az + u * ez)
            d = math.hypot(dx, dz)
            if d > 1e-9:
                px += dx / d * (push - d)
                pz += dz / d * (push - d)
        if px or pz:
            forward += 2.0 * (px * c + pz * s)
            lateral += 2.0 * (-px * s + pz * c)
        top = spec.top_speed
        advance = forward / top + 0.3 * (forward - vf)
        strafe = lateral / (0.5 * top) + 0.3 * (lateral - vr)
        return Command(advance=advance, rotate=rotate, strafe=strafe, fire=fire)

    def back_off(self) -> Command:
        return Command(advance=-0.3, rotate=self.reverse_turn)

    def unstick(self, view: "View", cmd: Command, strafe: bool = False) -> Command:
        """Pushing (or held still on a path) but not moving for a second: reverse and
        turn for 0.8 s, then replan.  ``strafe``: a hard sideways push counts as
        pushing too (a fight's moves are mostly sideways)."""
        tank = view.me
        t = view.t
        if t < self.reverse_until:
            back = self.free(view, tank.heading + math.pi, 8.0, (0.0,))
            ahead = self.free(view, tank.heading, 8.0, (0.0,))
            return self.drive(view, -4.0 if back >= ahead else 4.0, 0.0, self.reverse_turn)
        t0, x0, z0 = self.progress_at
        # pushing, or on a path and neither driving nor turning (a wall feeler holding
        # it still, facing the next waypoint past a corner)
        pushing = abs(cmd.advance) >= 0.3 or (strafe and abs(cmd.strafe) >= 0.6) or (
            self._on_path() and abs(cmd.rotate) < 0.1 and abs(tank.omega) < 0.1)
        if not pushing or not math.isfinite(x0) or math.hypot(tank.x - x0, tank.z - z0) > self.STUCK_MOVE:
            self.progress_at = (t, tank.x, tank.z)
            return cmd
        if t - t0 > 1.0:
            # back out the way there is room for, turning; then plan afresh from here
            self.reverse_until = t + 0.8
            self.reverse_turn = 1.0 if view.rng.random() < 0.5 else -1.0
            self.progress_at = (t + 0.8, math.nan, math.nan)
            self._replan()
            return self.drive(view, -4.0, 0.0, self.reverse_turn)
        return cmd


def trim(path: list[tuple[float, float]], x: float, z: float, reach: float = 3.0) -> None:
    """Drop the waypoints of ``path`` already within ``reach`` m of (x, z), keeping the last."""
    while len(path) > 1 and math.hypot(path[0][0] - x, path[0][1] - z) < reach:
        path.pop(0)
