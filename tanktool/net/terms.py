"""Host terms (Raft-like) and what a peer does when it finds itself alone.

Every host change raises the **term** by one on every peer (they all see the same
departures, so they agree without a vote); the host's NUMBER, NEW_PLAYER and TABLE
carry it, and every listener's CHALLENGE carries its term, host and player count.

A peer that lost players uncleanly — links closed or silent, not goodbyes — may be on
the side left behind: a host frozen (SIGSTOP) for longer than the silence while the
others elected a new one, or one side of a partition.  So it **probes**: it dials the
addresses of the players it lost, once every ``PROBE_EVERY`` for ``PROBE_TIME``, then
every ``PROBE_SLOW`` until ``PROBE_LONG`` (a partition may last), and reads their
CHALLENGE.  When one of them stands in the session that goes on — more players (a
majority, as Raft elects), or as many under a higher term, or as many under the same
term with a lower host number — it **steps down**: a host first tells its members where that
session is (a NOT_HOST refusal on their links, so they follow it), its computer
opponents are dropped (the new host adopted them: no duplicates), joiners are
redirected to that session, and ``Peer.rejoin`` joins it as a member (a new number).
So when a partition heals, every peer ends in the session of the highest (players,
term, lower host).  A peer left alone refuses joins with "try again" until its first round of
probes has been answered, so that a joiner dialling a stale host's address is not taken
into a split session.  (Two sides with as many players, the same term and hosts of the
same number stay apart: that tie has no winner.)  A member dropped by the
others (silence) that made itself host of its own session comes back the same way: the
larger session does not step down to it.  Two members that dropped each other while
the host kept both (a cut between them alone) find each other in their own session when
their probes get through; the higher number rejoins through the host.  No I/O: part of :class:`~tanktool.net.core.Core` (a probe is a
``Connect`` action; the answer comes back as any link's bytes).
"""

from __future__ import annotations

from typing import Any

from . import protocol as P
from .links import Connect, Link, NetEvent

#: how long after losing players a peer probes their addresses, and how often [s]:
#: often at first, then seldom for as long as a partition may last
PROBE_TIME = 6.0
PROBE_EVERY = 1.0
PROBE_SLOW = 5.0
PROBE_LONG = 60.0
#: a probe's connection gives up after this long [s]
PROBE_TIMEOUT = 1.0
#: why a player left that says nothing about the session going on elsewhere ("dropped
#: by the host" does: the host may have lost it to a partition, as we did not).  A player
#: our own judge found cheating is never followed, whatever its CHALLENGE claims
CLEAN = ("exit", "replaced", "cheating")


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
        self.probe_fast_until = -1.0
        self.next_probe = 0.0
        self.first_round = False
        self.step_down_to = None             # a newer session's member we will rejoin through
        #: members we dropped ourselves (silence, a closed link) while our host stayed:
        #: (ip, tcp port) -> their number.  Such a member answering a probe in our own
        #: session means the mesh is one-sided (the host kept both of us)
        self.dropped_members: dict[tuple[str, int], int] = {}

    def _others(self) -> list[int]:
        return [k for k, x in self.table.items() if not x.is_bot and k != self.number]  # type: ignore[attr-defined]

    def _lost_player(self, e: P.Entry, reason: str) -> None:
        """Called when player ``e`` left: if not by goodbyes, probe its address (and
        while that left us alone, hold joins until the first round is answered)."""
        if reason in CLEAN or reason.startswith("disconnected") or e.is_bot:
            return
        now = self.now                                             # type: ignore[attr-defined]
        self.lost[(e.ip, e.tcp_port)] = now
        if reason != "dropped by the host" and e.number != self.host_number \
                and not self.is_host and self.host_number in self.table:   # type: ignore[attr-defined]
            self.dropped_members[(e.ip, e.tcp_port)] = e.number
        if self.closed:                                            # type: ignore[attr-defined]
            return
        self._arm_probes(now)
        if not self._others():
            self.next_probe = now
            self.first_round = True

    def _probe_list(self) -> tuple[tuple[str, int], ...]:
        """The addresses we probe, the latest lost first, for the host's NUMBER,
        NEW_PLAYER and TABLE (at most MAX_PLAYERS)."""
        if self.now > self.probe_until:                            # type: ignore[attr-defined]
            return ()
        latest = sorted(self.lost, key=self.lost.__getitem__, reverse=True)
        return tuple(latest[:P.MAX_PLAYERS])

    def _take_probe_list(self, addresses: tuple[tuple[str, int], ...]) -> None:
        """The host's probe list: we probe those players too (without holding joins),
        so a member that joined after the loss still finds the other side of a
        partition if the host leaves or dies before its probes do."""
        here = {(e.ip, e.tcp_port) for e in self.table.values()}          # type: ignore[attr-defined]
        now = self.now                                                    # type: ignore[attr-defined]
        new = [a for a in addresses if a not in here and a not in self.lost]
        if not new or self.closed:                                        # type: ignore[attr-defined]
            return
        for a in new:
            self.lost[a] = now
        self._arm_probes(now)

    def _arm_probes(self, now: float) -> None:
        """Probe the lost addresses often for PROBE_TIME from now, then seldom up to
        PROBE_LONG (at once if no round was under way)."""
        if now > self.probe_until:
            self.next_probe = now
        self.probe_until = now + PROBE_LONG
        self.probe_fast_until = now + PROBE_TIME

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
        here = {(e.ip, e.tcp_port) for e in self.table.values()}          # type: ignore[attr-defined]
        for addr, when in list(self.lost.items()):
            if addr in here or now - when > PROBE_LONG:     # back with us, or given up on
                del self.lost[addr]
        if not self.lost:
            self.probe_until = -1.0
            self.first_round = False
            return
        self.next_probe = now + (PROBE_EVERY if now < self.probe_fast_until else PROBE_SLOW)
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
        # the session that goes on is the one with more players (a majority, as Raft
        # elects); between as many, the higher term; then the lower host number (both
        # sides see the same two numbers: two peers left alone do not stay apart).  A
        # member dropped by silence that made itself host of its own one-player session
        # (term + 1) draws nobody to it.  Our own term and host number is our own session
        # seen by a peer that has not caught up (a kicked player's last view): not another.
        # Alone we have no session to see late: the same two numbers are another's
        if (body.term, body.host) == (self.term, self.host_number) and self._others():
            self._one_sided(link.addr)
            return
        if body.players >= P.MAX_PLAYERS:
            return                 # a full session would refuse us: no reason to leave ours
        if (body.players, body.term, -body.host) > (len(self._others()) + 1, self.term, -self.host_number):
            if self.is_host:                     # type: ignore[attr-defined]
                # our members follow us there, rather than electing one of them
                redirect = self._pack(P.Refuse(P.RefuseCode.NOT_HOST, f"{link.addr[0]}:{link.addr[1]}"))  # type: ignore[attr-defined]
                for member in list(self.links.values()):                 # type: ignore[attr-defined]
                    if not member.outgoing:
                        self._queue(member, redirect)                    # type: ignore[attr-defined]
            self._step_down(link.addr, body.host, f"term {body.term} with {body.players} players at "
                                                  f"{link.addr[0]}:{link.addr[1]}")

    def _one_sided(self, addr: tuple[str, int]) -> None:
        """A member we dropped ourselves answers in our own session: it dropped us too,
        and the host kept both (each side holds the other as departed, so no table
        brings it back).  Of the two, the one with the higher number rejoins through the
        host, as a new player both sides will link to; the other waits for it."""
        other = self.dropped_members.pop(addr, None)
        host = self.table.get(self.host_number)                    # type: ignore[attr-defined]
        if other is None or host is None or self.is_host or self.number < other:  # type: ignore[attr-defined]
            return
        self._step_down((host.ip, host.tcp_port), self.host_number,
                        f"player {other} at {addr[0]}:{addr[1]} is in our session but not linked "
                        "to us: rejoining through the host")

    def _step_down(self, addr: tuple[str, int], host: int, why: str) -> None:
        self.step_down_to = addr
        self.first_round = False
        self.dropped["stepped_down"] += 1                          # type: ignore[attr-defined]
        self.events.append(NetEvent("stepdown", host, addr, why))  # type: ignore[attr-defined]

    def host_alone(self, address: tuple[str, int, int], now: float) -> None:
        """The rejoin after stepping down failed (that session's peer left or died on
        the way): host our own session again at ``address`` (ip, tcp, udp) and go on
        probing the players we lost, rather than end up in no session at all."""
        self.join_outcome = None                                      # type: ignore[attr-defined]
        self.start_host(address, now)                                 # type: ignore[attr-defined]
        # a term of our own: a lone host numbered 1 under the old term would read the
        # session it left (host 1 there too) as its own and never step down to it
        self.term += 1
        if self.lost:
            self._arm_probes(now)
            self.next_probe = now

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
        # the players we lost stay on the list: the session we join may be the smaller
        # side of a partition, and they the larger one
        self.first_round = False
        self.step_down_to = None
        self.used_numbers, self.freed, self.max_epoch = set(), [], 0   # type: ignore[attr-defined]
        # who left our old session says nothing about the new one (whose numbers and
        # epochs may repeat ours: both sides of a partition gave them)
        self.departed.clear()                                         # type: ignore[attr-defined]
        self.dropped_members.clear()
        self.addr_buckets.clear()                                     # type: ignore[attr-defined]
