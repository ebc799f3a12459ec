"""Charger: an example bot for tanktool (docs/bots.md).

It drives to where it last saw or heard an enemy (A* on the arena's grid), otherwise
from spawn point to spawn point; an enemy in sight it turns onto and charges, firing
when the gun points at it.  Written from docs/bots.md only.

    tanktool tournament --bot examples/bots/charger.py:Charger --bot easy
"""

import math

from tanktool.bots import Bot, Command


def turn_towards(me, x, z):
    """The rotate command and the heading error towards (x, z)."""
    err = math.remainder(math.atan2(z - me.z, x - me.x) - me.heading, math.tau)
    return max(-1.0, min(1.0, 2.5 * err - 0.5 * me.omega)), err


class Charger(Bot):
    think_hz = 10.0          # decide ten times a second; the command is held in between

    def __init__(self):
        self.path = []       # waypoints [(x, z), ...]
        self.goal = None

    def act(self, view):
        me = view.me
        if not me.alive:
            self.path, self.goal = [], None
            return Command()
        if view.seen:                                  # nearest enemy in sight: charge
            enemy = view.seen[0]
            rotate, err = turn_towards(me, enemy.x, enemy.z)
            close = enemy.distance < 15.0
            return Command(advance=-0.3 if close else 0.8, rotate=rotate,
                           fire=abs(err) < 0.04 and me.reload == 0.0)
        goal = self.pick_goal(view)
        if goal != self.goal or not self.path:
            self.goal, self.path = goal, view.map.path((me.x, me.z), goal)
        while self.path and math.hypot(self.path[0][0] - me.x, self.path[0][1] - me.z) < 3.0:
            self.path.pop(0)
        if not self.path:
            self.goal = None
            return Command(rotate=0.5)                 # nowhere to go: look around
        rotate, err = turn_towards(me, *self.path[0])
        return Command(advance=max(0.0, 1.0 - abs(err)), rotate=rotate)

    def pick_goal(self, view):
        """Where the enemy was last seen or heard (in the last 10 s), else a spawn point."""
        memory, t = view.memory, view.t
        recent = [s for s in memory.last_seen.values() if t - s.t < 10.0]
        if recent:
            s = max(recent, key=lambda s: s.t)
            return (s.x, s.z)
        if memory.heard is not None and t - memory.heard.t < 10.0:
            return (memory.heard.x, memory.heard.z)
        if self.goal is not None and self.path:
            return self.goal
        x, z, _ = view.map.spawns[view.rng.randrange(len(view.map.spawns))]
        return (x, z)
