"""Host terms (Raft-like) and what a peer does when it finds itself alone.

Every host change raises the **term** by one on every peer (they all see the same
departures, so they agree without a vote); the host's NUMBER, NEW_PLAYER and TABLE
carry it, and every listener's CHALLENGE carries its term, host and player count.

A peer that lost every other player at once — links closed or silent, not goodbyes —
may be the one left behind: a host frozen (SIGSTOP) for longer than the silence while
the others elected a new one, or the small side of a partition.  So it **probes**: it
dials the addresses of the players it lost, once every ``PROBE_EVERY`` for
``PROBE_TIME``, and reads their CHALLENGE.  When one of them stands in a newer session
— a higher term, or the same term with more players — it **steps down**: its
computer opponents are dropped (the new host adopted them: no duplicates), joiners
are redirected to that session, and :meth:`TermsMixin.rejoin` joins it as a member
(a new number).  Until its first round of probes has been answered, it refuses joins
with "try again" so that a joiner dialling a stale host's address is not taken into a
split session.  No I/O: part of :class:`~tanktool.net.core.Core` (a probe is a
``Connect`` action; the answer comes back as any link's bytes).
"""

from __future__ import annotations

from typing import Any

from . import protocol as P
from .links import Connect, Link, NetEvent

#: how long after losing everyone a peer probes their addresses, and how often [s]
PROBE_TIME = 6.0
PROBE_EVERY = 1.0
#: a probe's connection gives up after this long [s]
PROBE_TIMEOUT = 1.0
#: why a player left that says nothing about the session going on elsewhere
CLEAN = ("exit", "dropped by the host", "replaced")


class TermsMixin:
    """Terms, probes and stepping down, for :class:`~tanktool.net.core.Core`."""

    term: int
    lost: dict[tuple[str, int], float]
    probes: list[Any]
    probe_until: float
    next_probe: float
    first_round: bool
    step_down_to: tuple[str, int] | None

    def _init_terms(self) -> None:
        self.term = 1
        self.lost = {}                       # (ip, tcp port) of players lost uncleanly -> when
        self.probes = []                     # probe links open
        self.probe_until = -1.0
        self.next_probe = 0.0
        self.first_round = False
        self.step_down_to = None             # a newer session's member we will rejoin through

    def _others(self) -> list[int]:
        return [k for k, x in self.table.items() if not x.is_bot and k != self.number]  # type: ignore[attr-defined]

    def _lost_player(self, e: P.Entry, reason: str) -> None:
        """Called when player ``e`` left: if that left us alone and not by goodbyes, probe."""
        if reason in CLEAN or reason.startswith("disconnected") or e.is_bot:
            return
        now = self.now                                             # type: ignore[attr-defined]
        self.lost[(e.ip, e.tcp_port)] = now
        if not self._others() and not self.closed:                 # type: ignore[attr-defined]
            self.probe_until = now + PROBE_TIME
            self.next_probe = now
            self.first_round = True

    def probing(self) -> bool:
        """Whether joins wait: the first round of probes is not over yet."""
        return self.first_round and (bool(self.probes) or self.next_probe <= self.now)  # type: ignore[attr-defined]

    def _probe_tick(self, now: float) -> None:
        for link in list(self.probes):
            if now - link.opened > PROBE_TIMEOUT:
                self._end_probe(link)
        if self.step_down_to is not None or now > self.probe_until or now < self.next_probe:
            if not self.probes and now >= self.next_probe:
                self.first_round = False
            return
        if self._others():                       # someone is back (or joined): nothing to find
            self.probe_until = -1.0
            self.first_round = False
            return
        self.next_probe = now + PROBE_EVERY
        for addr in list(self.lost):
            self._dial_probe(addr, now)
        if not self.probes:
            self.first_round = False

    def _dial_probe(self, addr: tuple[str, int], now: float) -> None:
        link = self._new_link(addr, probe=True)                    # type: ignore[attr-defined]
        self.probes.append(link)
        self.actions.append(Connect(link.id, addr))                # type: ignore[attr-defined]

    def _end_probe(self, link: Any) -> None:
        self._close_link(link, "probe over")                       # type: ignore[attr-defined]
        if not self.probes and self.next_probe > self.now:         # type: ignore[attr-defined]
            self.first_round = False

    def _on_probe(self, link: Any, m: P.Message) -> None:
        """A probed address answered: a newer session there means we step down."""
        body = m.body
        self._end_probe(link)
        if not isinstance(body, P.Challenge) or self.step_down_to is not None:
            return
        mine = (self.term, len(self._others()) + 1)
        if (body.term, body.players) > mine:
            self.step_down_to = link.addr
            self.first_round = False
            self.dropped["stepped_down"] += 1                          # type: ignore[attr-defined]
            self.events.append(NetEvent("stepdown", body.host, link.addr,  # type: ignore[attr-defined]
                                        f"term {body.term} with {body.players} players at "
                                        f"{link.addr[0]}:{link.addr[1]}"))

    def forget_session(self, now: float) -> None:
        """Leave what is left of our session (our computer opponents with it) before
        joining another as a new member (:meth:`~tanktool.net.peer.Peer.rejoin`)."""
        self.now = now                                                # type: ignore[attr-defined]
        for link in list(self.conns.values()):                        # type: ignore[attr-defined]
            self._close_link(link, "rejoining")                       # type: ignore[attr-defined]
        self.table.clear()                                            # type: ignore[attr-defined]
        self.links.clear()                                            # type: ignore[attr-defined]
        self.last_heard.clear()                                       # type: ignore[attr-defined]
        self.last_state_seq.clear()                                   # type: ignore[attr-defined]
        self.window.anchors.clear()                                   # type: ignore[attr-defined]
        self.number = self.host_number = 0                            # type: ignore[attr-defined]
        self.lost.clear()
        self.probe_until = -1.0
        self.first_round = False
        self.step_down_to = None
        self.used_numbers, self.freed, self.max_epoch = set(), [], 0   # type: ignore[attr-defined]
