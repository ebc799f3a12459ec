"""A peer of a network session (paper §3.3): the player table, joins, the full mesh,
and host migration.

The first peer hosts.  A joiner opens TCP to the host and answers its challenge with a
join request; the host checks room (8 players), assigns the lowest free number and sends
the joiner its number and the whole table (number, name, address), and every other
peer the new table.  The joiner then opens a TCP link to every other peer (full mesh),
so any of them can take over.  TCP carries what must arrive (join, table, shots, hits,
exits); UDP carries tank states, latest sequence wins.

Host migration: a peer whose TCP link closes, or who is silent for ``silence`` seconds
(3 s), leaves every table on its own.  When the host leaves, the remaining peer with
the lowest number becomes host; all tables hold the same numbers, so all agree without
a vote.  The host's only duty is answering joins, so nothing else has to move.

Safety: a number is bound to a TCP link (the host's, or one the joiner opened to the
address in the host's table, or a HELLO whose number, epoch and IP match the table) and to
the UDP address in the table; anything a link or address sends for another number is
dropped and counted.  With a password, every link answers an HMAC-SHA256 challenge and
every datagram carries a tag made with the key of its link (:mod:`.auth`).  Messages are
size-checked by the protocol; states must carry sequence numbers within a window; links,
tanks and joins are rate-limited; unidentified connections are capped per address, and a
new one pushes out the oldest silent one (:mod:`.guard`).

The class is put together from its parts: :mod:`.handshake` (listening, joining),
:mod:`.joining` (admitting players, the table), :mod:`.datagrams` (states over UDP),
:mod:`.links` (bound links), :mod:`.terms` (host terms, stepping down); the limits are in
:mod:`.limits`.  Here: the peer's state, the poll loop, timeouts, leaving, reports.
"""

from __future__ import annotations

import selectors
import socket
import time
from collections import Counter, deque
from dataclasses import replace
from typing import Any, Callable

from ..errors import NetError
from . import protocol as P
from .auth import hello_mac, join_mac  # noqa: F401 (re-exported)
from .datagrams import DatagramsMixin
from .guard import Bucket, Buckets, DropLog, JoinLimiter, SeqWindow
from .handshake import JoinerMixin
from .joining import JoiningMixin
from .limits import (  # noqa: F401 - also here for those who tune or patch them (tests do)
    SILENCE, PENDING_TIMEOUT, HELLO_WAIT, MAX_HELLO_WAITING, MAX_PENDING, MAX_PENDING_PER_IP,
    ACCEPTS_PER_POLL, LISTEN_BACKLOG, TCP_RATE, TCP_BURST, UDP_RATE, UDP_BURST, UDP_READS,
    JOIN_RATE, JOIN_BURST, JOINS_RATE, JOINS_BURST, AUTH_FAIL_RATE, AUTH_FAIL_BURST, JOIN_SETTLE,
    JOIN_BUSY_WAIT, MAX_OUTBUF, LATENCY_SAMPLES,
)
from .links import Link, LinksMixin, NetEvent, free_port, parse_address, percentile  # noqa: F401 (re-exported)
from .names import name_problem, visible
from .terms import TermsMixin

__all__ = ["Peer", "NetEvent", "Link", "Bucket", "parse_address", "free_port", "join_mac", "hello_mac",
           "percentile"]


class Peer(JoinerMixin, JoiningMixin, DatagramsMixin, LinksMixin, TermsMixin):
    """One player's end of a session.  Build with :meth:`host` or :meth:`join`, then
    call :meth:`poll` often (it never blocks longer than its timeout)."""

    def __init__(self, name: str, password: str | None = None, clock: Callable[[], float] = time.time,
                 silence: float = SILENCE, digest: bytes = bytes(P.DIGEST_SIZE), label: str = "") -> None:
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
        #: the highest epoch ever seen: a new player's epoch is above it, never reused
        self.max_epoch = 0
        #: numbers ever given in this session, and the order the free ones were freed
        self.used_numbers: set[int] = set()
        self.freed: list[int] = []
        #: links whose send failed: dropped after the current message is handled, so a
        #: failure never pulls a player out of the table while a handler is using it
        self._failed: list[tuple[Link, str]] = []
        #: sockets of kicked players, half-closed, closed after their deadline
        self._linger: list[tuple[socket.socket, float]] = []
        self._init_terms()
        #: per member address: its datagram budget (rebuilt when the table changes)
        self.addr_buckets: dict[tuple, Bucket] = {}
        self.password = password or None
        self.clock = clock
        self.silence = silence
        self.number = 0
        self.table: dict[int, P.Entry] = {}
        self.host_number = 0
        self.links: dict[int, Link] = {}            # bound links by number
        self.pending: list[Link] = []
        self.departed: set[tuple[int, int]] = set()  # (number, epoch) that left
        self.last_heard: dict[int, float] = {}
        self.last_state_seq: dict[tuple[int, int], int] = {}
        self.window = SeqWindow()                   # sequence numbers a sender's states may carry
        self.state_buckets = Buckets(UDP_RATE, UDP_BURST)     # per (sender, tank)
        now = clock()
        self.joins = JoinLimiter((JOIN_RATE, JOIN_BURST), (JOINS_RATE, JOINS_BURST), now)
        self.auth_failures = Buckets(AUTH_FAIL_RATE, AUTH_FAIL_BURST)
        self.counters: Counter = Counter()          # sent, received, bytes_sent, bytes_received
        self.states_from: Counter = Counter()       # states taken, by sender
        self.dropped: DropLog = DropLog()           # reason -> count (and where from, for -v)
        self.latencies: deque[float] = deque(maxlen=LATENCY_SAMPLES)
        self.host_changes: list[tuple[float, int]] = []
        self.events: list[NetEvent] = []
        self.seq = 0
        self.session_offset = 0.0       # session time = clock() - session_offset
        self.sel = selectors.DefaultSelector()
        self.tcp: socket.socket | None = None
        self.udp: socket.socket | None = None
        self.closed = False
        self._backlog: list[P.Message] = []
        self._pruned = now

    # ------------------------------------------------------------------ set-up
    @property
    def tcp_address(self) -> tuple[str, int]:
        assert self.tcp is not None
        return self.tcp.getsockname()

    @property
    def udp_address(self) -> tuple[str, int]:
        assert self.udp is not None
        return self.udp.getsockname()

    @classmethod
    def host(cls, bind: tuple[str, int], name: str, password: str | None = None, **kw: Any) -> "Peer":
        """Start a session: listen on ``bind`` and become player 1, the host."""
        peer = cls(name, password, **kw)
        peer._listen(*bind)
        ip, tcp_port = peer.tcp_address
        peer.number = peer.host_number = 1
        peer.table = {1: P.Entry(1, 1, ip, tcp_port, peer.udp_address[1], name)}
        peer.max_epoch = 1
        peer.used_numbers = {1}
        peer.session_offset = peer.clock()
        return peer

    @classmethod
    def join(cls, address: tuple[str, int], name: str, password: str | None = None, timeout: float = 5.0,
             port: int = 0, link_wait: float = JOIN_SETTLE, **kw: Any) -> "Peer":
        """Join the session whose host (or any member, which redirects) is at ``address``.

        Listens on the interface that reaches the host, on ``port`` (0: any free one).
        A host that says "too many joins" is asked again every 0.5 s for ``timeout``
        seconds.  Before returning, waits up to ``link_wait`` seconds for the other members'
        challenges and answers them, so the mesh links do not depend on how soon the
        caller first polls.  Raises NetError with one clear line if the host cannot be
        reached or refuses.
        """
        peer = cls(name, password, **kw)
        try:
            peer._join_loop(address, timeout, port, time.monotonic() + timeout)
            peer._settle(link_wait)
            return peer
        except BaseException:
            peer.close(send_exit=False)
            raise

    def _pack(self, body: P.Body, kind: P.MessageType | None = None) -> bytes:
        self.seq += 1
        return P.encode(body, self.number, self.seq, self.clock(), kind=kind)

    def _pack_control(self, body: P.Body) -> bytes:
        """A challenge or refusal to a connection not yet bound: it carries the game
        counter without advancing it, so however many strangers knock, the members'
        window on this peer's states does not move (finding 3 of issue 27)."""
        return P.encode(body, self.number, self.seq, self.clock())

    # ------------------------------------------------------------------ queries
    @property
    def is_host(self) -> bool:
        return self.number != 0 and self.number == self.host_number

    def session_time(self) -> float:
        return self.clock() - self.session_offset

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
    def send_event(self, body: P.Body) -> None:
        """A shot, hit or exit to every linked peer, by TCP."""
        data = self._pack(body)
        for link in list(self.links.values()):
            self._queue(link, data)
        if not isinstance(body, P.Exit):
            self._reap()

    # ------------------------------------------------------------------ the loop
    def poll(self, timeout: float = 0.0) -> list[NetEvent]:
        """Handle everything that arrived (waiting at most ``timeout`` seconds for the
        first thing), check silences and pending links; return what happened."""
        if self.closed:
            return []
        self._service(timeout)
        out, self.events = self.events, []
        return out

    def _service(self, timeout: float) -> None:
        accept = False
        for key, mask in self.sel.select(max(timeout, 0.0)):
            if key.data == "accept":
                accept = True
            elif key.data == "udp":
                self._read_udp()
            else:
                link: Link = key.data
                if link.sock.fileno() < 0:
                    continue
                if mask & selectors.EVENT_WRITE:
                    self._flush(link)
                if mask & selectors.EVENT_READ and link.sock.fileno() >= 0 and not link.failed:
                    self._read_tcp(link)
                self._reap()
        # new connections last: one accepted at the previous poll has had its answer read
        # before any newer one can push it out of the pending list
        if accept:
            self._accept()
            self._reap()
        self._check_timeouts()
        self._probe_tick(self.clock())
        self._reap()

    def _make_room(self, ip: str) -> bool:
        """Room in the pending list for a connection from ``ip``: over the per-address
        cap, that address's oldest pending connection goes; over the overall cap, the
        busiest address's.  Refusals being flushed go first, then silent connections,
        then HELLOs waiting for the table.  A real player answers its challenge within a
        round trip; silent connections never do, so they cannot keep it out."""
        mine = [link for link in self.pending if link.addr[0] == ip]
        if len(mine) >= MAX_PENDING_PER_IP:
            victims = mine
        elif len(self.pending) >= MAX_PENDING:
            busiest = Counter(link.addr[0] for link in self.pending).most_common(1)[0][0]
            victims = [link for link in self.pending if link.addr[0] == busiest]
        else:
            return True
        if not victims:
            return False
        victim = min(victims, key=lambda link: (not link.closing, link.proven, link.hello is not None, link.opened))
        self.dropped.source = victim.addr[0]
        self.dropped["evicted"] += 1
        self._close_link(victim)
        return True

    # ------------------------------------------------------------------ leaving
    def _check_timeouts(self) -> None:
        now = self.clock()
        while self._linger and (self._linger[0][1] <= now or self.closed):
            self._linger.pop(0)[0].close()
        for link in list(self.pending):
            if now - link.opened > (HELLO_WAIT if link.hello is not None else PENDING_TIMEOUT):
                self.dropped.source = link.addr[0]
                self.dropped["pending_timeout"] += 1
                self._close_link(link)
        if now - self._pruned > 1.0:          # forget the buckets of addresses gone quiet
            self._pruned = now
            for buckets in (self.joins.addresses, self.auth_failures, self.state_buckets):
                buckets.prune(now)
        for n in list(self.table):
            if n in self.table and n != self.number and not self.table[n].is_bot \
                    and now - self.last_heard.get(n, now) > self.silence:
                self._remove(n, "silent")

    def _remove(self, n: int, reason: str) -> None:
        """Player ``n`` left (exit, closed link, silence): out of the table; if it was
        the host, the lowest remaining number hosts."""
        e = self.table.pop(n, None)
        self.addr_buckets.clear()
        link = self.links.get(n)
        if link is not None:
            self._close_link(link)
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
        self.events.append(NetEvent("left", n, e, reason))
        players = [k for k, x in self.table.items() if not x.is_bot]
        if n == self.host_number and players:
            self.host_number = min(players)
            self.term += 1                    # every peer sees the same departures: same term
            self.host_changes.append((self.session_time(), self.host_number))
            self.events.append(NetEvent("host", self.host_number))
        # its computer opponents go on, run by the host (the new one if it was the host)
        for k, x in list(self.table.items()):
            if x.owner == n:
                self.table[k] = replace(x, owner=self.host_number)
                if self.host_number == self.number:
                    self.events.append(NetEvent("adopt", k, self.table[k]))
        if self.is_host and self.links and not self.closed:
            table = self._pack(P.Assign(self.number, self.session_time(), self._table(), self.term),
                               P.MessageType.TABLE)
            for link in list(self.links.values()):
                if not link.outgoing:
                    self._queue(link, table)
        self._lost_player(e, reason)

    def close(self, send_exit: bool = True) -> None:
        """Leave: tell everyone (TCP), close every socket."""
        if self.closed:
            return
        if send_exit and self.links:
            self.send_event(P.Exit())
            for link in list(self.links.values()):
                if link.out:
                    try:
                        link.sock.setblocking(True)
                        link.sock.settimeout(0.5)
                        link.sock.sendall(link.out)
                    except OSError:
                        pass
        for link in list(self.links.values()) + list(self.pending):
            self._close_link(link)
        for sock, _ in self._linger:
            sock.close()
        self._linger.clear()
        for link in list(self.probes):
            self._end_probe(link)
        for s in (self.tcp, self.udp):
            if s is not None:
                try:
                    self.sel.unregister(s)
                except (KeyError, ValueError):
                    pass
                s.close()
        self.sel.close()
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


