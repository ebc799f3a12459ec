"""Sniper: an example bot for tanktool (docs/bots.md).

It picks, near where it spawned, the place that sees the most of the arena (the map's
sight table), drives there and watches, turning to every shot it hears; it shoots
an enemy in sight on the exact intercept (the shell keeps the shooter's velocity),
only within the shells' range; a shell flying at it makes it strafe out of the way.
Written from docs/bots.md only.

    tanktool tournament --bot examples/bots/sniper.py:Sniper --bot normal
"""

import math

from tanktool.bots import Bot, Command


def intercept(me, enemy, speed):
    """The heading that meets ``enemy`` (moving on as it moves) with a shell of
    ``speed`` fired now, and the flight time; None if it cannot be caught."""
    rx, rz = enemy.x - me.x, enemy.z - me.z
    vx, vz = enemy.vx - me.vx, enemy.vz - me.vz            # in our frame: the shell keeps our velocity
    a = vx * vx + vz * vz - speed * speed
    b = 2.0 * (rx * vx + rz * vz)
    c = rx * rx + rz * rz
    if abs(a) < 1e-9:
        return None
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return None
    times = [t for t in ((-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)) if t > 0]
    if not times:
        return None
    t = min(times)
    return math.atan2(rz + vz * t, rx + vx * t), t


def angle(a):
    return math.remainder(a, math.tau)


class Sniper(Bot):
    think_hz = 20.0

    def __init__(self):
        self.spot = None          # (x, z, way to face)
        self.path = []
        self.look_to = None       # (heading, until)

    def act(self, view):
        me = view.me
        if not me.alive:
            self.spot, self.path, self.look_to = None, [], None
            return Command()
        if self.spot is None:
            self.choose_spot(view)
        strafe = self.dodge(view)
        in_range = [s for s in view.seen if s.distance <= view.rules.shell_range]
        if in_range:
            enemy = in_range[0]
            aim = intercept(me, enemy, me.vehicle.shell_speed)
            heading = aim[0] if aim else math.atan2(enemy.z - me.z, enemy.x - me.x)
            err = angle(heading - me.heading)
            # fire when the shell would pass within a third of its width of the intercept
            miss = enemy.distance * abs(math.sin(err))
            fire = aim is not None and miss < 0.3 * (enemy.vehicle.box[3] - enemy.vehicle.box[1]) / 2 + 0.3
            return Command(rotate=self.turn(me, err), strafe=strafe, fire=fire and me.reload == 0.0)
        for h in view.heard:                           # a shot: look that way for 3 s
            self.look_to = (math.atan2(h.z - me.z, h.x - me.x), view.t + 3.0)
            break
        x, z, face = self.spot
        while self.path and math.hypot(self.path[0][0] - me.x, self.path[0][1] - me.z) < 2.5:
            self.path.pop(0)
        if self.path:                                  # on the way to the spot
            err = angle(math.atan2(self.path[0][1] - me.z, self.path[0][0] - me.x) - me.heading)
            return Command(advance=max(0.0, 0.8 - abs(err)), rotate=self.turn(me, err), strafe=strafe)
        if self.look_to is not None and view.t < self.look_to[1]:
            face = self.look_to[0]
        speed_ahead = me.vx * math.cos(me.heading) + me.vz * math.sin(me.heading)
        return Command(advance=-0.5 * speed_ahead, rotate=self.turn(me, angle(face - me.heading)), strafe=strafe)

    @staticmethod
    def turn(me, err):
        return max(-1.0, min(1.0, 2.5 * err - 0.6 * me.omega))

    def choose_spot(self, view):
        """The block within 40 m of path that sees the most blocks within the range."""
        me, table = view.me, view.map.sight_table()
        here = table.cell_at(me.x, me.z, me.y)
        if here < 0:
            self.spot = (me.x, me.z, me.heading)
            return
        reach = table.path_distances(here)
        best, score = here, -1
        for b in range(len(table.points)):
            if reach[b] <= 40.0:
                sees = int(((table.distance[b] <= view.rules.shell_range) & table.visible[b]).sum())
                if sees > score:
                    best, score = b, sees
        x, z = (float(v) for v in table.points[best])
        # face where most of what it sees lies
        seen = [(float(px) - x, float(pz) - z) for (px, pz), ok in zip(table.points, table.visible[best]) if ok]
        face = math.atan2(sum(d[1] for d in seen), sum(d[0] for d in seen)) if seen else me.heading
        self.spot = (x, z, face)
        self.path = view.map.path((me.x, me.z, me.y), (x, z, float(table.heights[best])))

    def dodge(self, view):
        """Strafe away from a shell passing within 3 m in the next 1.5 s (else 0)."""
        me = view.me
        for sh in view.shells:
            rx, rz = me.x - sh.x, me.z - sh.z
            vx, vz = sh.vx - me.vx, sh.vz - me.vz
            v2 = vx * vx + vz * vz
            t = (rx * vx + rz * vz) / v2 if v2 > 0 else -1.0
            if 0.0 < t < 1.5 and math.hypot(rx - vx * t, rz - vz * t) < 3.0:
                right = (-math.sin(me.heading), math.cos(me.heading))
                side = (rx - vx * t) * right[0] + (rz - vz * t) * right[1]   # which side of its line we are
                return 1.0 if side >= 0.0 else -1.0
        return 0.0
