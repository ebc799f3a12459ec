"""A simulated network for deterministic tests: a clock you advance, and links with
delay, jitter, loss, reordering and partitions, all drawn from one seeded generator.

Nothing here touches a socket or the wall clock::

    net = SimNet(seed=1, delay=0.05, jitter=0.15, loss=0.05)
    net.send("a", "b", payload)           # at net.now
    net.advance(0.01)
    for src, dst, payload in net.deliver():
        ...

``delay`` is the one-way base delay, ``jitter`` a uniform extra in [0, jitter) drawn per
message (so messages overtake each other: reordering comes from jitter, or from
``reorder`` which adds a further ``jitter`` to that fraction of messages), ``loss`` the
fraction dropped.  A partition cuts the pairs between two groups for a time span.

:class:`~tanktool.net.simcluster.SimCluster` runs protocol cores (:mod:`.core`) on such a network, as
:class:`~tanktool.net.peer.Peer` runs one on sockets: datagrams go through a
:class:`SimNet` (lost, delayed, reordered, cut), connections are reliable and ordered
(delayed by the same delay and jitter; what is sent across a cut arrives when it heals,
as TCP retransmits), a process can be paused (SIGSTOP: nothing it receives is read,
its clock stops) or killed (its connections close).  Everything is driven by one clock
and one seed::

    net = SimCluster(seed=1, delay=0.1, jitter=0.1, loss=0.05)
    host = net.host("alice")
    bob = net.join("bob", host)
    net.run(5.0)                          # each peer ticks, sends its states at 30 Hz
    assert sorted(bob.core.table) == [1, 2]
"""

from __future__ import annotations

import heapq
import random
from dataclasses import dataclass, field
from typing import Any, Hashable, Iterable


@dataclass(order=True)
class _InFlight:
    at: float
    order: int
    src: Hashable = field(compare=False)
    dst: Hashable = field(compare=False)
    payload: Any = field(compare=False)


class SimNet:
    """Messages between named endpoints, delivered by a simulated clock."""

    def __init__(self, seed: int = 0, delay: float = 0.0, jitter: float = 0.0, loss: float = 0.0,
                 reorder: float = 0.0) -> None:
        self.rng = random.Random(seed)
        self.delay, self.jitter, self.loss, self.reorder = delay, jitter, loss, reorder
        self.now = 0.0
        self._flight: list[_InFlight] = []
        self._order = 0
        self._cuts: list[tuple[float, float, frozenset, frozenset]] = []
        self.sent = 0
        self.lost = 0
        self.cut = 0

    def partition(self, start: float, end: float, side_a: Iterable[Hashable], side_b: Iterable[Hashable]) -> None:
        """From ``start`` to ``end`` nothing passes between ``side_a`` and ``side_b``."""
        self._cuts.append((start, end, frozenset(side_a), frozenset(side_b)))

    def _severed(self, src: Hashable, dst: Hashable, t: float) -> bool:
        for start, end, a, b in self._cuts:
            if start <= t < end and ((src in a and dst in b) or (src in b and dst in a)):
                return True
        return False

    def send(self, src: Hashable, dst: Hashable, payload: Any) -> None:
        """Send now; it arrives after the delay (or never)."""
        self.sent += 1
        if self._severed(src, dst, self.now):
            self.cut += 1
            return
        if self.loss and self.rng.random() < self.loss:
            self.lost += 1
            return
        extra = self.rng.random() * self.jitter if self.jitter else 0.0
        if self.reorder and self.rng.random() < self.reorder:
            extra += self.jitter
        self._order += 1
        heapq.heappush(self._flight, _InFlight(self.now + self.delay + extra, self._order, src, dst, payload))

    def advance(self, dt: float) -> None:
        self.now += dt

    def deliver(self) -> list[tuple[Hashable, Hashable, Any]]:
        """Everything due by now, in arrival order: (src, dst, payload)."""
        out = []
        while self._flight and self._flight[0].at <= self.now:
            m = heapq.heappop(self._flight)
            if self._severed(m.src, m.dst, m.at):
                self.cut += 1
                continue
            out.append((m.src, m.dst, m.payload))
        return out

    def pending(self) -> int:
        return len(self._flight)

    def heals(self, src: Hashable, dst: Hashable, t: float) -> float | None:
        """When the cut between ``src`` and ``dst`` at time ``t`` ends (None: not cut)."""
        ends = [end for start, end, a, b in self._cuts
                if start <= t < end and ((src in a and dst in b) or (src in b and dst in a))]
        return max(ends) if ends else None

