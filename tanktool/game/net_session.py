"""A network match in the game window: ``net.session.NetMatch`` with the face of a
:class:`~tanktool.game.session.GameSession`, so the views, HUD and sound draw it as
they draw a local match.

The match keeps its own real-time clock (``NetMatch.pump``): the window calls
:meth:`NetGameSession.advance` once a frame with the player's command; it reads the
network, takes the steps that are due (the local tank driven by that command, the
host's computer opponents by their bots, remote tanks placed from their states) and
sends the local tanks' states.  Only the tanks in the player table are shown.
"""

from __future__ import annotations

import math
import time
from collections import deque
from typing import Any

import numpy as np

from ..sim.commands import IDLE, Command
from .session import Effect, pose3d, update_effects, update_feed


class _Shown:
    """The match's world as the renderers see it: ``tanks`` lists the tanks that are in
    the session (the other slots of the 8 are empty); everything else is the world's."""

    def __init__(self, session: "NetGameSession") -> None:
        self._session = session

    @property
    def tanks(self) -> list[Any]:
        return [t for t in self._session.world_all.tanks if self._session.shown(t.index)]

    def __getattr__(self, name: str) -> Any:
        return getattr(self._session.world_all, name)


class NetGameSession:
    """One peer's side of a network match, shown in the window.

    Parameters
    ----------
    peer : a connected ``net.peer.Peer`` (``Peer.host`` or ``Peer.join``)
    arena, spec : ``sim.match.ArenaInfo`` and ``TankSpec`` (everyone should use the same)
    bots : computer opponents the host runs
    """

    realtime = True

    def __init__(self, peer: Any, arena: Any, spec: Any, seed: int = 0, bots: int = 0,
                 arena_ref: Any = None, vehicle_ref: Any = None) -> None:
        from ..net.session import NetMatch

        self.peer = peer
        self.log: deque[str] = deque(maxlen=6)
        self.command: Command = IDLE
        self.match = NetMatch(peer, arena, spec, seed=seed, driver=self._drive, bots=bots, log=self.log.append)
        self.world_all = self.match.world
        self.world = _Shown(self)
        self.info, self.spec = arena, spec
        self.arena_ref = arena_ref or arena.name
        self.vehicle_ref = vehicle_ref
        self.difficulty = "normal"
        self.player = peer.number - 1
        self.drivers: list[Any] = [None] * len(self.world_all.tanks)
        self.effects: list[Effect] = []
        self.feed: list[Any] = []
        self.last_events: list[Any] = []
        self.follow: int | None = None
        self.recorder = None             # a network match is not recorded
        self.max_steps: int | None = None
        self.prev = self._poses()
        self.closed = False
        self.report: dict[str, Any] | None = None
        self.match.begin()

    # ------------------------------------------------------------------ the match
    def _drive(self, world: Any, tank: Any) -> Command:
        return self.command

    def shown(self, i: int) -> bool:
        n = i + 1
        if n not in self.peer.table:
            return False
        return n in self.match._local() or n in self.match.remotes

    def _poses(self) -> list[tuple[float, float, float]]:
        return [(*t.position, t.heading) for t in self.world_all.tanks]

    def _before_step(self) -> None:
        self.prev = self._poses()

    def advance(self, command: Command = IDLE) -> list[Any]:
        """One turn of the match's real-time loop with the player's ``command``;
        returns the events of the steps it took."""
        if self.closed:
            return []
        self.command = command
        events = self.match.pump(before_step=self._before_step)
        if self.peer.number:          # a stale host that rejoined has a new number
            self.player = self.peer.number - 1
        w = self.world_all
        self.effects = update_effects(self.effects, events, w)
        self.feed = update_feed(self.feed, events, w.t)
        for n, name in self.match.names.items():     # the players' names on the scoreboard
            w.tanks[n - 1].name = name
        self.last_events = events
        return events

    def step(self, player_command: Command = IDLE) -> list[Any]:
        return self.advance(player_command)

    def close(self) -> dict[str, Any]:
        """Leave the session (EXIT to everyone); returns the match report."""
        if not self.closed:
            self.report = self.match.finish()
            self.peer.close()
            self.closed = True
        assert self.report is not None
        return self.report

    def summary(self) -> str:
        r = self.report or self.match.finish()
        net = r["network"]
        return (f"network: {r['seconds']:.1f} s as player {r['me']} of {len(r['peers'])}, host player {r['host']}; "
                f"sent {net['sent']}, received {net['received']}, dropped {net['dropped']}"
                + (f" ({', '.join(f'{k} {v}' for k, v in sorted(net['dropped_reasons'].items()))})"
                   if net.get("dropped_reasons") else ""))

    # ------------------------------------------------------------------ what GameSession offers
    @property
    def dt(self) -> float:
        return self.world_all.dt

    @property
    def t(self) -> float:
        return self.world_all.t

    def alpha(self) -> float:
        """How far real time is from the last step to the next (0..1)."""
        if not hasattr(self.match, "next_step"):
            return 1.0
        return min(max(1.0 - (self.match.next_step - time.monotonic()) / self.dt, 0.0), 1.0)

    def pose(self, i: int, alpha: float = 1.0) -> tuple[float, float, float]:
        x0, z0, h0 = self.prev[i]
        t = self.world_all.tanks[i]
        x1, z1 = t.position
        h1 = t.heading
        if math.hypot(x1 - x0, z1 - z0) > 5.0:
            return x1, z1, h1
        dh = math.remainder(h1 - h0, 2.0 * math.pi)
        return x0 + alpha * (x1 - x0), z0 + alpha * (z1 - z0), h0 + alpha * dh

    def pose3d(self, i: int, alpha: float = 1.0) -> tuple[float, float, float, float, float, float]:
        return pose3d(self, i, alpha)

    def shell_points(self, alpha: float = 1.0) -> np.ndarray:
        shells = self.world_all.shells
        if not shells:
            return np.zeros((0, 3))
        return np.array([(s.px + alpha * (s.x - s.px), s.py + alpha * (s.y - s.py), s.pz + alpha * (s.z - s.pz))
                         for s in shells])

    def focus(self) -> int:
        return self.player

    def focus_tank(self) -> Any:
        return self.world_all.tanks[self.player]

    def scoreboard(self) -> list[tuple[str, int, int, float, bool]]:
        """(name, kills, deaths, hit points, alive) best first, with the match's scores
        (each hit is decided by the host)."""
        rows = []
        for t in self.world.tanks:
            sc = self.match._score(t.index + 1)
            rows.append((t.name, sc.kills, sc.deaths, max(t.hp, 0.0), t.alive))
        return sorted(rows, key=lambda r: (-r[1], r[2]))
