"""Links, events and actions of the protocol core (:mod:`.core`), and the plumbing of
links: queueing, closing, reading what a link says and dispatching it.  No socket: a
link is a number the transport (:mod:`.peer`, or a simulated network) maps to its
connection; sending and closing are *actions* the transport performs.  Part of
:class:`~tanktool.net.core.Core`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

from ..errors import NetError
from . import limits as L     # read at call time: tests patch the limits
from . import protocol as P
from .auth import datagram_key, hello_mac
from .guard import Bucket


def parse_address(text: str, default_host: str = "127.0.0.1", need_host: bool = False) -> tuple[str, int]:
    """``[ADDR:]PORT`` -> (dotted IPv4, port); NetError (one line) if malformed."""
    text = text.strip()
    host, sep, port_s = text.rpartition(":")
    if not sep:
        if need_host:
            raise NetError(f"{text!r}: expected ADDR:PORT, e.g. 127.0.0.1:5000")
        host, port_s = default_host, text
    host = host or default_host
    if host == "localhost":
        host = "127.0.0.1"
    try:
        port = int(port_s)
    except ValueError:
        raise NetError(f"{text!r}: the port must be a number from 0 to 65535") from None
    if not 0 <= port <= 65535 or (need_host and port == 0):
        raise NetError(f"{text!r}: the port must be a number from {1 if need_host else 0} to 65535")
    parts = host.split(".")
    if len(parts) != 4 or not all(p.isdigit() and int(p) <= 255 for p in parts):
        raise NetError(f"{text!r}: {host!r} is not an IPv4 address (e.g. 127.0.0.1)")
    return host, port


# ---------------------------------------------------------------- actions (core -> transport)
class Send(NamedTuple):
    """Write ``data`` (whole messages) on link ``link``."""
    link: int
    data: bytes


class SendTo(NamedTuple):
    """Send one datagram to ``addr`` (ip, udp port)."""
    addr: tuple
    data: bytes


class Close(NamedTuple):
    """Close link ``link`` once what was sent on it is flushed.  ``linger`` > 0: then
    half-close and keep the connection that long (closing with the other end's unread
    messages in our buffer would reset it and lose the last message: a kick's reason)."""
    link: int
    reason: str = ""
    linger: float = 0.0


class Connect(NamedTuple):
    """Open a connection to ``addr`` (ip, tcp port) for link ``link``; if it fails,
    tell the core ``disconnected(link)``."""
    link: int
    addr: tuple


Action = Send | SendTo | Close | Connect


@dataclass
class Link:
    """A connection as the core sees it: pending until it says who it is, then bound to
    one number."""

    id: int
    reader: P.StreamReader
    bucket: Bucket
    opened: float
    addr: tuple = ("", 0)             # the other end (ip, port)
    nonce: bytes = b""
    number: int = 0                   # bound player number (0 while pending)
    udp_key: bytes | None = None      # with a password: the key of this pair's datagrams
    hello: P.Message | None = None    # a HELLO waiting for the table to know its number
    closing: bool = False             # refused: nothing it says counts any more
    outgoing: bool = False            # a mesh link we opened, waiting for its challenge
    initiated: bool = False           # a mesh link we opened (for simultaneous opens)
    refused: bool = False             # the other end refused this link: its closing is no exit
    proven: bool = False              # it answered the password challenge right (a HELLO waiting)
    probe: bool = False               # we dialled a lost player's address to read its term (terms.py)
    joining: bool = False             # our own join request's link (handshake.py)
    join_mac: bytes = b""             # the MAC our JOIN carried (the datagram key derives from it)
    join_sent: float | None = None    # when our JOIN went out (None: waiting for the challenge)


@dataclass(frozen=True)
class NetEvent:
    """What the core saw: ``kind`` is joined, left, host, state (``reason`` "respawn"
    when the judge saw it come back), shot, hit, adopt, kicked, cheater (the host
    disconnected it) or stepdown."""

    kind: str
    number: int
    body: Any = None
    reason: str = ""


def percentile(values: list[float], q: float) -> float:
    """The q-th percentile (0..100) by nearest rank; NaN for no values."""
    if not values:
        return math.nan
    s = sorted(values)
    k = min(len(s) - 1, max(0, int(math.ceil(q / 100.0 * len(s))) - 1))
    return s[k]


class LinksMixin:
    """Links: queue, close, drop; read and dispatch what they say."""

    def _new_link(self, addr: tuple, **kw: Any) -> Link:
        self._next_link += 1
        link = Link(self._next_link, P.StreamReader(self.dropped), Bucket(L.TCP_RATE, L.TCP_BURST, self.now),
                    self.now, addr=addr, **kw)
        self.conns[link.id] = link
        return link

    def _queue(self, link: Link, data: bytes) -> None:
        if link.id not in self.conns:
            return
        self.counters["sent"] += 1
        self.counters["bytes_sent"] += len(data)
        self.actions.append(Send(link.id, data))

    def _drop_link(self, link: Link, reason: str) -> None:
        """The connection of ``link`` closed or failed (``reason``)."""
        if link.probe:
            self._end_probe(link)
            return
        if link.joining:
            self._join_failed(link, reason)
            return
        if link.outgoing or link.refused:
            # a mesh link that never opened says nothing about its peer: silence will
            self.dropped["link_failed"] += 1
            self._close_link(link)
        elif link.number and self.links.get(link.number) is link:
            self._remove(link.number, reason)
        else:
            if reason == "garbage":
                self.dropped["garbage_stream"] += 1
            self._close_link(link)

    def _close_link(self, link: Link, reason: str = "", linger: float = 0.0) -> None:
        if self.conns.pop(link.id, None) is None:
            return
        self.actions.append(Close(link.id, reason, linger))
        if link in self.pending:
            self.pending.remove(link)
        if link in self.probes:
            self.probes.remove(link)
        if link.number and self.links.get(link.number) is link:
            del self.links[link.number]

    def _bind_link(self, link: Link, number: int) -> None:
        link.number = number
        self.links[number] = link
        self.last_heard[number] = self.now

    def received(self, link_id: int, data: bytes, now: float) -> None:
        """Bytes arrived on a link (``b""``: the other end closed it)."""
        self.now = now
        link = self.conns.get(link_id)
        if link is None:
            return
        self.dropped.source = link.addr[0]
        if not data:
            self._drop_link(link, "closed")
            return
        self.counters["bytes_received"] += len(data)
        for m in link.reader.feed(data):
            if link.id not in self.conns:
                return
            if not link.bucket.take(now):
                self.dropped["rate"] += 1
                continue
            self._on_tcp(link, m)
        if link.reader.broken and link.id in self.conns:
            self._drop_link(link, "garbage")

    def disconnected(self, link_id: int, reason: str, now: float) -> None:
        """A link's connection closed or failed (a send, a connect, too slow)."""
        self.now = now
        link = self.conns.get(link_id)
        if link is not None:
            self._drop_link(link, reason)

    def _on_tcp(self, link: Link, m: P.Message) -> None:
        if link.probe:
            self._on_probe(link, m)
            return
        if link.joining:
            self._on_join_answer(link, m)
            return
        if link.closing:
            return
        if link.number == 0:
            self._on_pending(link, m)
            return
        if link.outgoing:
            if not isinstance(m.body, P.Challenge) or m.sender != link.number:
                self._drop_link(link, "garbage")
                return
            link.outgoing = False
            epoch = self.table[self.number].epoch
            mac = hello_mac(self.password, m.body.nonce, self.number, epoch) if self.password else bytes(P.MAC_SIZE)
            if self.password:
                link.udp_key = datagram_key(self.password, mac)
            self.window.anchor(link.number, m.seq, self.now)
            self._queue(link, self._pack(P.Hello(epoch, mac)))
            return
        if m.sender != link.number:
            self.dropped["impostor"] += 1      # a peer speaks only for its own number
            return
        self.window.anchor(link.number, m.seq, self.now)     # the link is authenticated: its numbers are real
        self._on_bound(link, m)

    def _on_bound(self, link: Link, m: P.Message) -> None:
        """What a bound, authenticated link said."""
        if isinstance(m.body, P.Refuse) and link.initiated:
            link.refused = True                # a duplicate link lost the tie-break
            return
        if isinstance(m.body, P.Refuse) and m.sender == self.host_number and not self.is_host \
                and m.body.code == P.RefuseCode.NOT_HOST:
            # our host stepped down to a newer session (terms.py): follow it there
            try:
                addr = parse_address(m.body.text, need_host=True)
            except NetError:
                self.dropped["garbage"] += 1
                return
            if self.step_down_to is None:
                self._step_down(addr, m.sender, f"the host moved to the session at {addr[0]}:{addr[1]}")
            return
        if isinstance(m.body, P.Refuse) and m.sender == self.host_number and not self.is_host:
            # the host disconnected us (a kick): leave, rather than elect ourselves
            self.events.append(NetEvent("kicked", m.sender, reason=m.body.text))
            self.leave(self.now, send_exit=False)
            return
        self.counters["received"] += 1
        self.last_heard[link.number] = self.now
        body = m.body
        if m.type in (P.MessageType.NEW_PLAYER, P.MessageType.TABLE):
            if m.sender != self.host_number:
                self.dropped["not_host"] += 1
                return
            # the host's term is its session's: members that saw departures in another
            # order (and so counted host changes differently) take it (terms.py)
            self.term = body.term
            if m.type == P.MessageType.TABLE:
                # the host's table is the reference: who is not in it has left (for
                # example a player whose EXIT reached only the host)
                keep = {e.number for e in body.table.entries}
                for n in list(self.table):
                    if n not in keep and n != self.number:
                        self._remove(n, "dropped by the host")
            self._merge_table(body.table, body.number)
            self._take_probe_list(body.lost)
        elif isinstance(body, P.Shot):
            if not self._may_speak(m.sender, body.tank):
                self.dropped["impostor"] += 1
                return
            if self.judge is not None and self.judge.shot(body, self.session_time()) is not None:
                return                         # refused (too soon, from afar, dead): the judge counts it
            self.events.append(NetEvent("shot", m.sender, body))
        elif isinstance(body, P.Hit):
            if m.sender != self.host_number:     # only the host decides a hit
                self.dropped["not_host"] += 1
                return
            if self.judge is not None:
                self.judge.hit(body.victim, body.hp, body.killed, body.t)
            self.events.append(NetEvent("hit", m.sender, body))
        elif isinstance(body, P.Exit):
            self._remove(link.number, "exit")
        elif isinstance(body, P.State):
            self._on_state(m, self.now)            # allowed on TCP too (e.g. through firewalls)
        else:
            self.dropped["unexpected"] += 1

