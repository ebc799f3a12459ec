"""A bot written only from docs/bots.md (issue 31's "done when"): it is not part of
the package and uses nothing but the documented API.

Hunter turns onto an enemy it sees and fires when lined up; otherwise it follows an
A* path to where it last saw or heard one, else wanders to a random spawn point.
"""

import math

from tanktool.bots import Bot, Command


class Hunter(Bot):
    think_hz = 20.0

    def __init__(self):
        self.path = []
        self.goal = None

    def steer(self, me, x, z):
        err = math.remainder(math.atan2(z - me.z, x - me.x) - me.heading, math.tau)
        return err, max(-1.0, min(1.0, 3.0 * err))

    def act(self, view):
        me = view.me
        if not me.alive:                  # dead: forget the plan
            self.path, self.goal = [], None
            return Command()
        if view.seen:
            enemy = view.seen[0]
            err, turn = self.steer(me, enemy.x, enemy.z)
            return Command(advance=0.6 if enemy.distance > 25 else 0.0, rotate=turn,
                           fire=abs(err) < 0.05 and me.reload == 0.0)
        target = None
        if view.memory.last_seen:
            last = max(view.memory.last_seen.values(), key=lambda s: s.t)
            target = (last.x, last.z)
        elif view.heard:
            target = (view.heard[0].x, view.heard[0].z)
        if target is None and not self.path:
            sx, sz, _ = view.map.spawns[view.rng.randrange(len(view.map.spawns))]
            target = (sx, sz)
        if target is not None and target != self.goal:
            self.goal = target
            self.path = view.map.path((me.x, me.z), target)
        while self.path and math.hypot(self.path[0][0] - me.x, self.path[0][1] - me.z) < 1.5:
            self.path.pop(0)
        if not self.path:
            self.goal = None
            return Command(advance=0.2, rotate=0.6)
        _, turn = self.steer(me, *self.path[0])
        return Command(advance=0.9 if abs(turn) < 0.5 else 0.3, rotate=turn)


class Broken(Bot):
    """Raises on every call: the match must go on and count the failures."""

    def act(self, view):
        raise RuntimeError("this bot is broken on purpose")
