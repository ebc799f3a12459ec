"""Remote tanks drawn from buffered states.

States arrive at ~30 Hz with their sender's session time (all peers share the host's
session clock).  A remote tank is shown ``delay`` seconds in the past (100 ms: three
updates), interpolated between the two buffered states around that time, so a lost or
late datagram does not make it jump.  Past the newest state it is extrapolated along its
velocity for at most ``max_extrapolation`` and then held.  Across a death or a respawn
(``alive`` changes) there is no interpolation: the tank appears where it respawned.
"""

from __future__ import annotations

import math
from collections import deque

from .protocol import State

INTERP_DELAY = 0.1
MAX_EXTRAPOLATION = 0.25


def _lerp_angle(a: float, b: float, u: float) -> float:
    d = math.remainder(b - a, 2.0 * math.pi)
    return math.remainder(a + u * d, 2.0 * math.pi)


class RemoteTank:
    """The buffered states of one remote tank."""

    def __init__(self, size: int = 32, max_extrapolation: float = MAX_EXTRAPOLATION) -> None:
        self.states: deque[State] = deque(maxlen=size)
        self.max_extrapolation = max_extrapolation

    def push(self, s: State) -> None:
        """Add a state; one older than the newest is dropped (the peer checks sequence
        numbers, this guards the session time)."""
        if self.states and s.t <= self.states[-1].t:
            return
        self.states.append(s)

    def sample(self, t: float) -> State | None:
        """The tank as it was at session time ``t``, or None before any state."""
        st = self.states
        if not st:
            return None
        if t <= st[0].t:
            return st[0]
        last = st[-1]
        if t >= last.t:
            if not last.alive:
                return last
            dt = min(t - last.t, self.max_extrapolation)
            return State(last.tank, t, last.x + last.vx * dt, last.z + last.vz * dt,
                         math.remainder(last.heading + last.omega * dt, 2.0 * math.pi),
                         last.vx, last.vz, last.omega, last.hp, last.alive)
        # newest first: the bracket is almost always at the end
        for k in range(len(st) - 1, 0, -1):
            a, b = st[k - 1], st[k]
            if a.t <= t <= b.t:
                if a.alive != b.alive or not a.alive:
                    return a
                u = (t - a.t) / (b.t - a.t) if b.t > a.t else 1.0
                return State(a.tank, t, a.x + u * (b.x - a.x), a.z + u * (b.z - a.z),
                             _lerp_angle(a.heading, b.heading, u), a.vx + u * (b.vx - a.vx),
                             a.vz + u * (b.vz - a.vz), a.omega + u * (b.omega - a.omega),
                             b.hp if u >= 0.5 else a.hp, a.alive)
        return last      # pragma: no cover - the brackets cover [first, last]
