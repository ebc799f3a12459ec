"""Links and events of a peer: the TCP connection record, what a poll reports, the
address helpers, and the plumbing of bound links (queueing, flushing, failing, closing,
reading, and handling what a bound link says).  Part of :class:`~tanktool.net.peer.Peer`."""

from __future__ import annotations

import math
import selectors
import socket
from dataclasses import dataclass, field
from typing import Any

from ..errors import NetError
from . import protocol as P
from .auth import datagram_key, hello_mac
from .guard import Bucket
from .limits import MAX_OUTBUF

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
    try:
        socket.inet_aton(host)
        if host.count(".") != 3:
            raise OSError
    except OSError:
        raise NetError(f"{text!r}: {host!r} is not an IPv4 address (e.g. 127.0.0.1)") from None
    return host, port


def free_port(ip: str = "127.0.0.1") -> int:
    """A port number free on ``ip`` for both TCP and UDP, as a host needs (for scripts
    and tests that start a host in another process; another program may still take it)."""
    for _ in range(50):
        t, u = socket.socket(), socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            t.bind((ip, 0))
            port = t.getsockname()[1]
            u.bind((ip, port))
            return port
        except OSError:
            continue
        finally:
            t.close()
            u.close()
    raise NetError(f"no port free for both TCP and UDP on {ip}")


class _Busy(NetError):
    """The host said "too many joins": ``Peer.join`` waits a little and asks again."""


@dataclass
class Link:
    """A TCP connection: pending until it says who it is, then bound to one number."""

    sock: socket.socket
    reader: P.StreamReader
    bucket: Bucket
    opened: float
    addr: tuple = ("", 0)             # the other end (ip, port)
    nonce: bytes = b""
    number: int = 0                   # bound player number (0 while pending)
    udp_key: bytes | None = None      # with a password: the key of this pair's datagrams
    hello: P.Message | None = None    # a HELLO waiting for the table to know its number
    out: bytearray = field(default_factory=bytearray)
    closing: bool = False             # close once ``out`` is flushed (after a refusal)
    outgoing: bool = False            # a mesh link we opened, waiting for its challenge
    initiated: bool = False           # a mesh link we opened (for simultaneous opens)
    refused: bool = False             # the other end refused this link: its closing is no exit
    failed: bool = False              # a send failed: dropped at the end of the current handler
    proven: bool = False              # it answered the password challenge right (a HELLO waiting)
    probe: bool = False               # we dialled a lost player's address to read its term (terms.py)


@dataclass(frozen=True)
class NetEvent:
    """What a poll saw: ``kind`` is joined, left, host, state, shot or hit."""

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
    """Bound links: queue, flush, fail, close; read and dispatch what they say."""

    def _queue(self, link: Link, data: bytes) -> None:
        if link.failed:
            return
        link.out += data
        self.counters["sent"] += 1
        self.counters["bytes_sent"] += len(data)
        self._flush(link)

    def _flush(self, link: Link) -> None:
        if link.failed:
            return
        if link.out:
            try:
                n = link.sock.send(link.out)
                del link.out[:n]
            except (BlockingIOError, InterruptedError):
                pass
            except OSError:
                self._fail(link, "closed")
                return
        if len(link.out) > MAX_OUTBUF:
            self._fail(link, "too slow")
            return
        want = selectors.EVENT_READ | (selectors.EVENT_WRITE if link.out else 0)
        try:
            if self.sel.get_key(link.sock).events != want:
                self.sel.modify(link.sock, want, link)
        except (KeyError, ValueError):
            pass
        if link.closing and not link.out:
            self._close_link(link)

    def _fail(self, link: Link, reason: str) -> None:
        """A send on ``link`` failed: it is dropped by :meth:`_reap` once the message
        being handled is done (dropping it here could take its player out of the
        table in the middle of admitting another: the KeyError of finding 2)."""
        if not link.failed:
            link.failed = True
            link.out.clear()
            self._failed.append((link, reason))

    def _reap(self) -> None:
        while self._failed:
            link, reason = self._failed.pop(0)
            self._drop_link(link, reason)

    def _drop_link(self, link: Link, reason: str) -> None:
        if link.probe:
            self._end_probe(link)
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

    def _close_link(self, link: Link) -> None:
        try:
            self.sel.unregister(link.sock)
        except (KeyError, ValueError):
            pass
        link.sock.close()
        if link in self.pending:
            self.pending.remove(link)
        if link.number and self.links.get(link.number) is link:
            del self.links[link.number]

    def _bind_link(self, link: Link, number: int, registered: bool = False) -> None:
        link.number = number
        self.links[number] = link
        self.last_heard[number] = self.clock()
        if registered:
            self._flush(link)
        else:
            self.sel.register(link.sock, selectors.EVENT_READ, link)
            if link.out:
                self._flush(link)

    def _read_tcp(self, link: Link) -> None:
        try:
            data = link.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        self.dropped.source = link.addr[0]
        if not data:
            self._drop_link(link, "closed")
            return
        self.counters["bytes_received"] += len(data)
        msgs = link.reader.feed(data)
        now = self.clock()
        for m in msgs:
            if link.sock.fileno() < 0:
                return
            if not link.bucket.take(now):
                self.dropped["rate"] += 1
                continue
            self._on_tcp(link, m)
            self._reap()
        if link.reader.broken:
            self._drop_link(link, "garbage")

    def _on_tcp(self, link: Link, m: P.Message) -> None:
        now = self.clock()
        if link.probe:
            self._on_probe(link, m)
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
            self.window.anchor(link.number, m.seq, now)
            self._queue(link, self._pack(P.Hello(epoch, mac)))
            return
        if m.sender != link.number:
            self.dropped["impostor"] += 1      # a peer speaks only for its own number
            return
        self.window.anchor(link.number, m.seq, now)     # the link is authenticated: its numbers are real
        if isinstance(m.body, P.Refuse) and link.initiated:
            link.refused = True                # a duplicate link lost the tie-break
            return
        if isinstance(m.body, P.Refuse) and m.sender == self.host_number and not self.is_host:
            # the host disconnected us (a kick): leave, rather than elect ourselves
            self.events.append(NetEvent("kicked", m.sender, reason=m.body.text))
            self.close(send_exit=False)
            return
        self.counters["received"] += 1
        self.last_heard[link.number] = now
        body = m.body
        if m.type == P.MessageType.NEW_PLAYER:
            if m.sender != self.host_number:
                self.dropped["not_host"] += 1
                return
            self.term = max(self.term, body.term)
            self._merge_table(body.table, body.number)
        elif m.type == P.MessageType.TABLE:
            if m.sender != self.host_number:
                self.dropped["not_host"] += 1
                return
            self.term = max(self.term, body.term)
            # the host's table is the reference: who is not in it has left (for
            # example a player whose EXIT reached only the host)
            keep = {e.number for e in body.table.entries}
            for n in list(self.table):
                if n not in keep and n != self.number:
                    self._remove(n, "dropped by the host")
            self._merge_table(body.table, body.number)
        elif isinstance(body, P.Shot):
            if not self._may_speak(m.sender, body.tank):
                self.dropped["impostor"] += 1
                return
            self.events.append(NetEvent("shot", m.sender, body))
        elif isinstance(body, P.Hit):
            if m.sender != self.host_number:     # only the host decides a hit
                self.dropped["not_host"] += 1
                return
            self.events.append(NetEvent("hit", m.sender, body))
        elif isinstance(body, P.Exit):
            self._remove(link.number, "exit")
        elif isinstance(body, P.State):
            self._on_state(m, now)            # allowed on TCP too (e.g. through firewalls)
        else:
            self.dropped["unexpected"] += 1
