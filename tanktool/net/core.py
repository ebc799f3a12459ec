"""The protocol of a peer without I/O (paper §3.3): the player table, joins, the full
mesh, terms and host migration, silences, kicks, and which states and shots are taken.

As h11 and wsproto do for HTTP and WebSocket, the core owns no socket, selector or
clock: the caller feeds it what happened, with the time, and performs what it asks::

    core = Core("alice")
    core.start_host(("127.0.0.1", 5000, 5000), now=0.0)
    link = core.accepted(("10.0.0.2", 40000), now=0.1)      # a connection came in
    for action in core.take_actions():                        # Send(link, challenge bytes)
        ...
    core.received(link, data, now=0.2)                         # bytes on that connection
    core.datagram(("10.0.0.2", 40001), data, now=0.3)          # a datagram
    core.tick(now=0.4)                                         # timers: silences, probes
    events = core.take_events()                                # NetEvent: joined, state, ...

Events in: :meth:`accepted`, :meth:`joining`, :meth:`received` (bytes, or ``b""`` when
the other end closed), :meth:`disconnected` (a connection failed), :meth:`datagram`,
:meth:`tick`; and the game's :meth:`send_state`, :meth:`send_event`, :meth:`add_bot`,
:meth:`kick`, :meth:`leave`.  Actions out (:mod:`.links`): ``Send(link, bytes)``,
``SendTo(addr, bytes)``, ``Close(link, reason, linger)``, ``Connect(link, addr)``.
:class:`~tanktool.net.peer.Peer` performs them on real sockets; tests/test_net_core.py
on a simulated network (:mod:`.simnet`).

The first peer hosts.  A joiner opens TCP to the host and answers its challenge with a
join request; the host checks room, assigns a number and an epoch never used in the
session, and sends the joiner its number and the whole table, and every other peer the
new table.  The joiner then links to every other member (full mesh), so any of them can
take over.  TCP carries what must arrive (join, table, shots, hits, exits); UDP carries
tank states, latest sequence wins.  A peer whose link closes, or who is silent for
``silence`` seconds, leaves every table on its own; when the host leaves, the lowest
remaining number hosts and the term rises (:mod:`.terms`).

Safety: a number is bound to a link (the host's, one the joiner opened to the address in
the host's table, or a HELLO whose number, epoch and IP match the table) and to the UDP
address in the table; anything else is dropped and counted (:attr:`dropped`).  With a
password, every link answers an HMAC-SHA256 challenge and every datagram carries a tag
made with its link's key (:mod:`.auth`).  The parts: :mod:`.handshake` (joining),
:mod:`.joining` (admitting, the table), :mod:`.datagrams`, :mod:`.links`, :mod:`.terms`;
the limits are in :mod:`.limits`.
"""

from __future__ import annotations

import os
from collections import Counter, deque
from dataclasses import replace
from typing import Any, Callable

from ..errors import NetError
from . import limits as L
from . import protocol as P
from .datagrams import DatagramsMixin
from .guard import Buckets, DropLog, JoinLimiter, SeqWindow
from .handshake import JoinerMixin, JoinOutcome
from .joining import JoiningMixin
from .links import Action, Link, LinksMixin, NetEvent
from .names import name_problem, visible
from .terms import TermsMixin

__all__ = ["Core", "JoinOutcome", "NetEvent", "Link"]


class Core(JoinerMixin, JoiningMixin, DatagramsMixin, LinksMixin, TermsMixin):
    """One player's protocol state.  Become host with :meth:`start_host`, or join with
    :meth:`joining`; then feed it events and perform :meth:`take_actions`."""

    def __init__(self, name: str, password: str | None = None, silence: float = L.SILENCE,
                 digest: bytes = bytes(P.DIGEST_SIZE), label: str = "", now: float = 0.0,
                 nonce_source: Callable[[int], bytes] = os.urandom) -> None:
        P.name_bytes(name)      # validates the name early, with a clear message
        if not name.isprintable():      # the protocol refuses such names: say so here
            raise NetError(f"the name {visible(name)} has characters that are not printable")
        problem = name_problem(name, [])
        if problem is not None:
            raise NetError(problem)
        if len(digest) != P.DIGEST_SIZE:
            raise ValueError(f"the match digest must be {P.DIGEST_SIZE} bytes")
        self.name = name
        #: the arena + vehicle this peer plays (net/digest.py): a host refuses joiners on others
        self.digest = bytes(digest)
        self.label = label                  # what the digest is of, for the refusal text
        self.password = password or None
        self.silence = silence
        #: challenges' nonces (os.urandom; a seeded source in simulations)
        self.nonce_source = nonce_source
        self.now = now
        #: the highest epoch ever seen: a new player's epoch is above it, never reused
        self.max_epoch = 0
        #: numbers ever given in this session, and the order the free ones were freed
        self.used_numbers: set[int] = set()
        self.freed: list[int] = []
        self._init_terms()
        #: per member address: its datagram budget (rebuilt when the table changes)
        self.addr_buckets: dict[tuple, Any] = {}
        self.number = 0
        self.table: dict[int, P.Entry] = {}
        self.host_number = 0
        self.conns: dict[int, Link] = {}            # every open link by its id
        self._next_link = 0
        self.links: dict[int, Link] = {}            # bound links by player number
        self.pending: list[Link] = []
        self.departed: set[tuple[int, int]] = set()  # (number, epoch) that left
        self.last_heard: dict[int, float] = {}
        self.last_state_seq: dict[tuple[int, int], int] = {}
        self.window = SeqWindow()                   # sequence numbers a sender's states may carry
        self.state_buckets = Buckets(L.UDP_RATE, L.UDP_BURST)     # per (sender, tank)
        self.joins = JoinLimiter((L.JOIN_RATE, L.JOIN_BURST), (L.JOINS_RATE, L.JOINS_BURST), now)
        self.auth_failures = Buckets(L.AUTH_FAIL_RATE, L.AUTH_FAIL_BURST)
        self.counters: Counter = Counter()          # sent, received, bytes_sent, bytes_received
        self.states_from: Counter = Counter()       # states taken, by sender
        self.dropped: DropLog = DropLog()           # reason -> count (and where from, for -v)
        self.latencies: deque[float] = deque(maxlen=L.LATENCY_SAMPLES)
        self.host_changes: list[tuple[float, int]] = []
        self.events: list[NetEvent] = []
        self.actions: list[Action] = []
        self.join_outcome: JoinOutcome | None = None
        self.join_ports = (0, 0)
        self.seq = 0
        self.session_offset = 0.0       # session time = now - session_offset
        self.closed = False
        self._pruned = now
        #: a new host sends its table (and term) again then: members that were still
        #: waiting out the old host's silence dropped the first one
        self.announce_at: float | None = None
        #: what every state and shot from the network goes through (a :class:`~.judge.Judge`
        #: on the game's world; None: taken as they come)
        self.judge: Any = None

    def start_host(self, address: tuple[str, int, int], now: float) -> None:
        """Start a session as player 1, the host, reachable at (ip, tcp port, udp port)."""
        self.now = now
        ip, tcp_port, udp_port = address
        self.number = self.host_number = 1
        self.table = {1: P.Entry(1, 1, ip, tcp_port, udp_port, self.name)}
        self.max_epoch = 1
        self.used_numbers = {1}
        self.session_offset = now

    def take_actions(self) -> list[Action]:
        """What the transport must do now, in order (and forget)."""
        out, self.actions = self.actions, []
        return out

    def take_events(self) -> list[NetEvent]:
        """What happened since the last call, for the game."""
        out, self.events = self.events, []
        return out

    def _pack(self, body: P.Body, kind: P.MessageType | None = None) -> bytes:
        self.seq += 1
        return P.encode(body, self.number, self.seq, self.now, kind=kind)

    def _pack_control(self, body: P.Body) -> bytes:
        """A challenge or refusal to a connection not yet bound: it carries the game
        counter without advancing it, so however many strangers knock, the members'
        window on this peer's states does not move (finding 3 of issue 27)."""
        return P.encode(body, self.number, self.seq, self.now)

    # ------------------------------------------------------------------ queries
    @property
    def is_host(self) -> bool:
        return self.number != 0 and self.number == self.host_number

    def session_time(self) -> float:
        return self.now - self.session_offset

    def players(self) -> list[P.Entry]:
        """Every table entry (players and computer opponents), by number."""
        return [self.table[n] for n in sorted(self.table)]

    def speaks_for(self) -> list[int]:
        """The tanks this peer runs: its own and the computer opponents it owns."""
        return [n for n in sorted(self.table) if n == self.number or self.table[n].owner == self.number]

    def _may_speak(self, sender: int, tank: int) -> bool:
        e = self.table.get(tank)
        return tank == sender or (e is not None and e.owner == sender)

    # ------------------------------------------------------------------ sending
    def send_event(self, body: P.Body, now: float) -> None:
        """A shot, hit or exit to every linked peer, by TCP."""
        self.now = now
        data = self._pack(body)
        for link in list(self.links.values()):
            self._queue(link, data)

    def _make_room(self, ip: str) -> bool:
        """Room in the pending list for a connection from ``ip``: over the per-address
        cap, that address's oldest pending connection goes; over the overall cap, the
        busiest address's.  Silent connections go first, then HELLOs waiting for the
        table.  A real player answers its challenge within a round trip; silent
        connections never do, so they cannot keep it out."""
        mine = [link for link in self.pending if link.addr[0] == ip]
        if len(mine) >= L.MAX_PENDING_PER_IP:
            victims = mine
        elif len(self.pending) >= L.MAX_PENDING:
            busiest = Counter(link.addr[0] for link in self.pending).most_common(1)[0][0]
            victims = [link for link in self.pending if link.addr[0] == busiest]
        else:
            return True
        if not victims:
            return False
        victim = min(victims, key=lambda link: (link.proven, link.hello is not None, link.opened))
        self.dropped.source = victim.addr[0]
        self.dropped["evicted"] += 1
        self._close_link(victim, "evicted")
        return True

    # ------------------------------------------------------------------ timers
    def tick(self, now: float) -> None:
        """Time passed: pending connections that said nothing in time, silent players,
        probes (:mod:`.terms`)."""
        self.now = now
        if self.closed:
            return
        for link in list(self.pending):
            if now - link.opened > (L.HELLO_WAIT if link.hello is not None else L.PENDING_TIMEOUT):
                self.dropped.source = link.addr[0]
                self.dropped["pending_timeout"] += 1
                self._close_link(link, "timeout")
        if now - self._pruned > 1.0:          # forget the buckets of addresses gone quiet
            self._pruned = now
            for buckets in (self.joins.addresses, self.auth_failures, self.state_buckets):
                buckets.prune(now)
        for n in list(self.table):
            if n in self.table and n != self.number and not self.table[n].is_bot \
                    and now - self.last_heard.get(n, now) > self.silence:
                self._remove(n, "silent")
        if self.judge is not None and self.is_host:
            self._kick_cheaters()
        if self.announce_at is not None and now >= self.announce_at:
            self.announce_at = None
            if self.is_host:
                self._send_table()
        self._probe_tick(now)

    def _kick_cheaters(self) -> None:
        """The host disconnects a member the judge corrected too often for too long."""
        t = self.session_time()
        for e in self.players():
            if e.number != self.number and not e.is_bot and self.judge.to_kick(e.number, t):
                why = f"corrected more than {self.judge.config.kick_rate} times a second for " \
                      f"{self.judge.config.kick_seconds} seconds"
                self.kick(e.number, why, self.now)
                self.events.append(NetEvent("cheater", e.number, e, why))

    def _forget(self, n: int) -> None:
        """Player ``n`` joined or left: the judge starts it afresh."""
        if self.judge is not None:
            self.judge.forget(n)

    # ------------------------------------------------------------------ leaving
    def _remove(self, n: int, reason: str) -> None:
        """Player ``n`` left (exit, closed link, silence): out of the table; if it was
        the host, the lowest remaining number hosts."""
        e = self.table.pop(n, None)
        self.addr_buckets.clear()
        link = self.links.get(n)
        if link is not None:
            self._close_link(link, reason)
        self.last_heard.pop(n, None)
        for key in [k for k in self.last_state_seq if n in k]:
            del self.last_state_seq[key]
        for key in [k for k in self.state_buckets.buckets if n in k]:
            self.state_buckets.forget(key)
        self.window.forget(n)
        if e is None:
            return
        self.departed.add((n, e.epoch))
        self.freed.append(n)
        # a player our own judge would kick is not probed once gone: whatever session
        # it claims to stand in, we do not follow it there
        cheat = self.judge is not None and not e.is_bot and self.judge.to_kick(n, self.session_time())
        self._forget(n)
        self.events.append(NetEvent("left", n, e, reason))
        players = [k for k, x in self.table.items() if not x.is_bot]
        if n == self.host_number and players:
            self.host_number = min(players)
            self.term += 1                    # every peer sees the same departures: same term
            self.host_changes.append((self.session_time(), self.host_number))
            self.events.append(NetEvent("host", self.host_number))
            if self.is_host:
                # once every member has timed out what we did, tell them our term again
                self.announce_at = self.now + self.silence
        # its computer opponents go on, run by the host (the new one if it was the host)
        for k, x in list(self.table.items()):
            if x.owner == n:
                self.table[k] = replace(x, owner=self.host_number)
                if self.host_number == self.number:
                    self.events.append(NetEvent("adopt", k, self.table[k]))
        if self.is_host:
            self._send_table()
        self._lost_player(e, "cheating" if cheat else reason)

    def _send_table(self) -> None:
        """The host's table (and term) to every member."""
        if not self.links or self.closed:
            return
        table = self._pack(P.Assign(self.number, self.session_time(), self._table(), self.term,
                                    self._probe_list()), P.MessageType.TABLE)
        for link in list(self.links.values()):
            if not link.outgoing:
                self._queue(link, table)

    def leave(self, now: float, send_exit: bool = True) -> None:
        """Leave: an EXIT to everyone linked (``send_exit``), every link closed."""
        self.now = now
        if self.closed:
            return
        if send_exit and self.links:
            self.send_event(P.Exit(), now)
        for link in list(self.conns.values()):
            self._close_link(link, "leaving")
        self.closed = True

    def reset_stats(self) -> None:
        """Restart the traffic counters and latency samples (a benchmark's window);
        drop reasons are kept."""
        self.counters.clear()
        self.states_from.clear()
        self.latencies.clear()

    def network_report(self) -> dict[str, Any]:
        """Counters for reports: messages sent / received / dropped, bytes, reasons."""
        return {
            "sent": self.counters["sent"], "received": self.counters["received"],
            "dropped": sum(self.dropped.values()),
            "bytes_sent": self.counters["bytes_sent"], "bytes_received": self.counters["bytes_received"],
            "state_rounds": self.counters["state_rounds"],
            "states_sent": self.counters["states_sent"], "states_received": self.counters["states_received"],
            "states_unkeyed": self.counters["states_unkeyed"],
            "states_received_by_sender": {str(k): v for k, v in sorted(self.states_from.items())},
            "dropped_reasons": dict(sorted(self.dropped.items())),
        }
