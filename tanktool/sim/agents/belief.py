"""Where the enemy may be: a possibility over the sight table's blocks, for the hunt.

The sight memory (``sight.Coverage``) says what has not been looked at lately; this
says where an enemy can be, from everything the agent learnt (1: as likely as
anywhere, 0: not there):

* at the start, at a spawn point (not the agent's own); after a kill in the feed, the
  dead one comes back at a spawn point;
* a sighting or a sound puts it on the block it came from, and makes the rest
  ``1 - SEEN`` (``1 - HEARD``) as likely;
* between them it spreads along the blocks' links as fast as a tank roams
  (``PACE`` of the top speed; a block takes the most of its neighbours', less
  ``DECAY`` a link): a front, not a diffusion -- a tank drives straight on, and a
  random walk's sqrt(t) spread left the enemy outside the belief for most of a
  duel in the maze (the belief at its block a tenth of the average);
* a block in the agent's cone with nobody seen in it keeps ``MISSED`` of it, and is
  filled again from its neighbours as the front comes back.

``goal`` is the hunt's target: the block whose sight holds the most of it per metre
of the way there (plus ``D0`` m: the look itself).  A camper waiting near its spawn
is found where a sweep of stale places would leave it for last; an enemy lost is
looked for where it can have got to by now, not in every quadrant in turn.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from .sight import Views

#: the enemy roams at this share of its top speed
PACE = 0.6
#: a link of the front costs this share of the possibility
DECAY = 0.97
#: a block looked at with nobody seen there keeps this much of its possibility
MISSED = 0.1
#: a sighting (a shot or engine heard) leaves the rest of the blocks this much less
#: likely (there may be other enemies; a sound's place is rough)
SEEN = 0.9
HEARD = 0.7
#: a search is over once the belief's mean is above this (it may be anywhere)
LOST = 0.5
#: the way's cost of the look itself [m] (goal: possibility in sight per metre + D0)
D0 = 30.0


class Belief:
    """See the module docstring.  ``views``: the sight table; ``spawns``: (x, z, y or
    None) of the spawn points."""

    def __init__(self, views: "Views", spawns: list[tuple[float, float, float | None]]) -> None:
        self.views = views
        n = len(views)
        pairs = [(a, b, w) for a, nb in enumerate(views.neighbours) for b, w in nb]
        self.src = np.asarray([a for a, _, _ in pairs], dtype=np.int64)
        self.dst = np.asarray([b for _, b, _ in pairs], dtype=np.int64)
        #: the mean link [m]: the front moves a link per this much of the enemy's way
        self.link = float(np.mean([w for _, _, w in pairs])) if pairs else math.inf
        cells = [views.cell_at(x, z, y) for x, z, y in spawns]
        self.spawn_cells = np.asarray(sorted({c for c in cells if c >= 0}), dtype=np.int64)
        self.p = np.ones(n)
        self.t = -math.inf
        self.way = 0.0          # metres driven by the enemy not yet spread

    def start(self, t: float, here: int) -> None:
        """At the match's start: on the spawn points but the agent's own block."""
        self.p = self._spawned(exclude=here)
        self.t = t

    def _spawned(self, exclude: int = -1) -> np.ndarray:
        p = np.full(len(self.views), 0.01)       # a floor: a spawn point off the blocks
        p[self.spawn_cells[self.spawn_cells != exclude]] = 1.0
        return p

    def spread(self, t: float, top_speed: float) -> None:
        """Move the front on by the way an enemy roams since the last spread."""
        if not math.isfinite(self.t):
            self.t = t
        self.way += (t - self.t) * PACE * top_speed
        self.t = t
        while self.way >= self.link:
            self.way -= self.link
            reach = np.zeros(len(self.p))
            np.maximum.at(reach, self.dst, self.p[self.src] * DECAY)
            np.maximum(self.p, reach, out=self.p)

    def looked(self, cells: Any) -> None:
        """Nobody was seen in ``cells`` (the blocks just in sight)."""
        if len(cells):
            self.p[cells] *= MISSED

    def at(self, cells: list[int], weight: float) -> None:
        """Enemies seen (``SEEN``) or heard (``HEARD``) in ``cells`` this think (all
        at once: one after another, each would wipe out the one before)."""
        cells = [c for c in cells if c >= 0]
        if cells:
            self.p *= 1.0 - weight
            self.p[cells] = 1.0

    def respawned(self) -> None:
        """An enemy died: it comes back at a spawn point."""
        np.maximum(0.2 * self.p, self._spawned(), out=self.p)

    def spread_out(self) -> bool:
        """The enemy may be anywhere in most of the arena (``LOST`` of it on
        average): a search for it has nothing to go on any more."""
        return len(self.p) == 0 or float(self.p.mean()) > LOST

    def goal(self, sees: np.ndarray, here: int) -> tuple[int, float] | None:
        """(block, the possibility in its sight) to go and look from: the most in sight
        (``sees``: the sight table's blocks-in-range matrix) per metre of the way there
        + ``D0``; None when ``here`` is off the blocks."""
        if here < 0:
            return None
        gain = sees @ self.p
        dist = self.views.path_distances(here)
        score = np.where(np.isfinite(dist), gain / (dist + D0), -1.0)
        best = int(np.argmax(score))
        return (best, float(gain[best])) if score[best] > 0.0 else None

    def gain(self, sees: np.ndarray, cell: int) -> float:
        """The possibility in sight of ``cell``."""
        return float(sees[cell] @ self.p)
