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
"""

from __future__ import annotations

import errno
import hmac
import math
import os
import selectors
import socket
import time
from collections import Counter, deque
from dataclasses import dataclass, field, replace
from typing import Any, Callable

from ..errors import NetError
from . import protocol as P
from .auth import TAG_SIZE, datagram_key, hello_mac, join_mac, seal, unseal
from .guard import Bucket, Buckets, DropLog, JoinLimiter, SeqWindow
from .names import name_problem, visible
from .terms import TermsMixin

__all__ = ["Peer", "NetEvent", "Link", "Bucket", "parse_address", "free_port", "join_mac", "hello_mac",
           "percentile"]

#: a peer silent this long has left (and if it hosted, the host migrates) [s]
SILENCE = 3.0
#: an accepted TCP connection must say JOIN or HELLO within this time [s]: a real peer
#: answers the challenge within a round trip (a joiner answers its mesh links' challenges
#: before ``Peer.join`` returns)
PENDING_TIMEOUT = 2.0
#: a HELLO waits this long for the host's NEW_PLAYER to name its number [s]
HELLO_WAIT = 5.0
#: HELLOs waiting at once for a number the table does not know yet: a real joiner's
#: waits a round trip at most (the host's NEW_PLAYER is on its way), so a few suffice;
#: more would let parked HELLOs crowd real joiners out of the pending list
MAX_HELLO_WAITING = 4
#: unidentified connections at once, and from one address; past either, a new connection
#: closes the oldest silent one (of the busiest address), so silent connections cannot
#: lock a real player out: it answers within a round trip, they never do
MAX_PENDING = 64
MAX_PENDING_PER_IP = 48
#: connections accepted per poll, after the data of those already open has been read (so
#: a new one is read before ACCEPTS_PER_POLL more can push it out)
ACCEPTS_PER_POLL = 16
LISTEN_BACKLOG = 128
#: per link / per tank message rates: a tank state at 30 Hz, a few events
TCP_RATE, TCP_BURST = 100.0, 200.0
UDP_RATE, UDP_BURST = 90.0, 45.0
#: datagrams read per poll at most (a poll comes every step, 120 a second)
UDP_READS = 1024
#: joins (host): per address a burst that lets a whole LAN party (or a loopback test
#: session) in at once, then one a second; overall, what many addresses together get
JOIN_RATE, JOIN_BURST = 1.0, 10.0
JOINS_RATE, JOINS_BURST = 5.0, 20.0
#: wrong passwords per address before its answers are no longer even checked
AUTH_FAIL_RATE, AUTH_FAIL_BURST = 1.0, 10.0
#: how long ``Peer.join`` waits for its mesh links' challenges before it returns [s]
JOIN_SETTLE = 1.0
#: how long ``Peer.join`` keeps retrying a host that says "too many joins" [s]
JOIN_BUSY_WAIT = 0.5
MAX_OUTBUF = 256 * 1024
LATENCY_SAMPLES = 200_000


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


class Peer(TermsMixin):
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
    def _listen(self, ip: str, port: int) -> None:
        """A TCP listener and a UDP socket on ip (TCP on ``port``, UDP on the same
        number when free)."""
        tcp = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        tcp.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            tcp.bind((ip, port))
            tcp.listen(LISTEN_BACKLOG)
            try:
                udp.bind((ip, tcp.getsockname()[1]))
            except OSError:
                if port:       # the user asked for this port: UDP must have it too
                    raise
                udp.bind((ip, 0))
        except OSError as e:
            tcp.close()
            udp.close()
            what = "in use" if e.errno in (98, 48, 10048) else f"not available ({e.strerror})"
            raise NetError(f"cannot listen on {ip}:{port}: address {what}") from None
        tcp.setblocking(False)
        udp.setblocking(False)
        udp.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        self.tcp, self.udp = tcp, udp
        self.sel.register(tcp, selectors.EVENT_READ, "accept")
        self.sel.register(udp, selectors.EVENT_READ, "udp")

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

    def _join_loop(self, address: tuple[str, int], timeout: float, port: int, busy_until: float) -> None:
        """Ask ``address`` to join, following redirects and waiting out "busy"."""
        redirects = 0
        while True:
            try:
                redirect = self._join_once(address, timeout, port)
            except _Busy as e:
                if time.monotonic() + JOIN_BUSY_WAIT > busy_until:
                    raise NetError(str(e)) from None
                time.sleep(JOIN_BUSY_WAIT)
                continue
            if redirect is None:
                return
            redirects += 1       # a member that is not the host names it: follow
            if redirects >= 3:
                raise NetError(f"cannot join: redirected too many times (last {redirect[0]}:{redirect[1]})")
            address = redirect

    def _settle(self, seconds: float) -> None:
        """Poll until every mesh link this joiner opened has had its challenge answered
        (or failed), for at most ``seconds``; what happened waits for the next poll."""
        end = time.monotonic() + seconds
        while any(link.outgoing for link in self.links.values()):
            left = end - time.monotonic()
            if left <= 0:
                break
            self._service(min(left, 0.01))

    def _join_once(self, address: tuple[str, int], timeout: float, port: int) -> tuple[str, int] | None:
        where = f"{address[0]}:{address[1]}"
        try:
            sock = socket.create_connection(address, timeout=timeout)
        except OSError as e:
            raise NetError(f"cannot reach {where}: {e.strerror or e}") from None
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        reader = P.StreamReader(self.dropped)
        deadline = time.monotonic() + timeout
        try:
            msg = self._read_blocking(sock, reader, deadline, where)
            if not isinstance(msg.body, P.Challenge):
                raise NetError(f"{where} did not answer like a tanktool peer")
            if msg.body.password and not self.password:
                raise NetError(f"{where} wants a password (--password)")
            if self.tcp is None:
                self._listen(sock.getsockname()[0], port)
            mac = join_mac(self.password, msg.body.nonce, self.name) if self.password else bytes(P.MAC_SIZE)
            sent_at = self.clock()
            self._send_blocking(sock, P.Join(self.name, self.tcp_address[1], self.udp_address[1], mac, self.digest))
            msg = self._read_blocking(sock, reader, deadline, where)
        except BaseException:
            sock.close()
            raise
        if isinstance(msg.body, P.Refuse):
            sock.close()
            if msg.body.code == P.RefuseCode.RATE:
                raise _Busy(f"join refused by {where}: {visible(msg.body.text)}")
            if msg.body.code == P.RefuseCode.NOT_HOST:
                try:
                    return parse_address(visible(msg.body.text), need_host=True)
                except NetError:
                    raise NetError(f"{where} is not the host and did not say who is") from None
            raise NetError(f"join refused by {where}: {visible(msg.body.text)}")
        if msg.type != P.MessageType.NUMBER or msg.sender != msg.body.table.host:
            sock.close()
            raise NetError(f"{where} did not answer the join request")
        body: P.Assign = msg.body
        now = self.clock()
        self.number = body.number
        self.host_number = body.table.host
        self.term = body.term
        # the session clock: the host's, plus half the round trip
        self.session_offset = now - (body.session_t + 0.5 * (now - sent_at))
        for e in body.table.entries:
            if e.number == self.host_number and e.ip == "0.0.0.0":
                e = P.Entry(e.number, e.epoch, address[0], e.tcp_port, e.udp_port, e.name)   # reach it as dialled
            self.table[e.number] = e
            self._saw(e)
        sock.setblocking(False)
        link = Link(sock, reader, Bucket(TCP_RATE, TCP_BURST, now), now, addr=address, nonce=b"")
        if self.password:
            link.udp_key = datagram_key(self.password, mac)
        self.window.anchor(self.host_number, msg.seq, now)
        self._bind_link(link, self.host_number)
        # the joiner links to those in the table it was given; who joins after it (a
        # NEW_PLAYER maybe already in the backlog) links to it
        members = [e for n, e in sorted(self.table.items())
                   if n not in (self.number, self.host_number) and not e.is_bot]
        self._drain_backlog(link)
        for e in members:
            if e.number in self.table and e.number not in self.links:
                self._link_to(e)
        return None

    def _link_to(self, e: P.Entry) -> None:
        """Open the mesh link to a table member (the joiner opens them all).  Non-blocking:
        two peers joining at once must not wait on each other.  The link is bound to
        ``e.number`` at once (we dialled the address the host's table gives for it) and
        answers the member's challenge with a HELLO when it comes."""
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        err = sock.connect_ex((e.ip, e.tcp_port))
        if err not in (0, errno.EINPROGRESS, errno.EWOULDBLOCK):
            sock.close()
            self.dropped["link_failed"] += 1      # it will time out of the table if really gone
            return
        now = self.clock()
        link = Link(sock, P.StreamReader(self.dropped), Bucket(TCP_RATE, TCP_BURST, now), now,
                    addr=(e.ip, e.tcp_port), outgoing=True, initiated=True)
        self._bind_link(link, e.number)

    def _drain_backlog(self, link: Link) -> None:
        backlog, self._backlog = self._backlog, []
        for m in backlog:
            self._on_tcp(link, m)

    def _read_blocking(self, sock: socket.socket, reader: P.StreamReader, deadline: float,
                       where: str) -> P.Message:
        while True:
            msgs = reader.feed(b"")
            if msgs:
                # a message that came in the same segment waits for the bound link
                self._backlog.extend(msgs[1:])
                return msgs[0]
            if reader.broken:
                raise NetError(f"{where} sent something that is not a tanktool message")
            left = deadline - time.monotonic()
            if left <= 0:
                raise NetError(f"{where} did not answer in time")
            sock.settimeout(left)
            try:
                data = sock.recv(4096)
            except socket.timeout:
                raise NetError(f"{where} did not answer in time") from None
            except OSError as e:
                raise NetError(f"{where}: {e.strerror or e}") from None
            if not data:
                raise NetError(f"{where} closed the connection")
            self.counters["bytes_received"] += len(data)
            reader.buffer += data

    def _pack(self, body: P.Body, kind: P.MessageType | None = None) -> bytes:
        self.seq += 1
        return P.encode(body, self.number, self.seq, self.clock(), kind=kind)

    def _pack_control(self, body: P.Body) -> bytes:
        """A challenge or refusal to a connection not yet bound: it carries the game
        counter without advancing it, so however many strangers knock, the members'
        window on this peer's states does not move (finding 3 of issue 27)."""
        return P.encode(body, self.number, self.seq, self.clock())

    def _saw(self, e: P.Entry) -> None:
        """Note an entry's epoch and number as used (never given again)."""
        self.addr_buckets.clear()            # the tanks per address may have changed
        self.max_epoch = max(self.max_epoch, e.epoch)
        self.used_numbers.add(e.number)
        if e.number in self.freed:
            self.freed.remove(e.number)

    def _new_slot(self) -> tuple[int, int] | None:
        """(number, epoch) for a newcomer: a number never used in this session while
        there is one, else the one freed longest ago; an epoch above every one seen.
        None when full."""
        free = [n for n in range(1, P.MAX_PLAYERS + 1) if n not in self.table]
        if not free:
            return None
        fresh = [n for n in free if n not in self.used_numbers]
        if fresh:
            n = fresh[0]
        else:
            order = [k for k in self.freed if k in free]
            n = order[0] if order else free[0]
        return n, self.max_epoch + 1

    def _send_blocking(self, sock: socket.socket, body: P.Body) -> None:
        data = self._pack(body)
        sock.sendall(data)
        self.counters["sent"] += 1
        self.counters["bytes_sent"] += len(data)

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

    def add_bot(self, name: str) -> int | None:
        """The host adds a computer opponent (it runs it): its number, or None when full."""
        if not self.is_host:
            raise NetError("only the host adds computer opponents")
        slot = self._new_slot()
        if slot is None:
            return None
        n, epoch = slot
        me = self.table[self.number]
        taken = [e.name for e in self.table.values()]
        base, k = name, 1
        while name_problem(name, taken) is not None:     # a player already took "bot1"
            k += 1
            name = f"{base}-{k}"
        self.table[n] = P.Entry(n, epoch, me.ip, me.tcp_port, me.udp_port, name, owner=self.number)
        self._saw(self.table[n])
        news = self._pack(P.Assign(n, self.session_time(), self._table(), self.term), P.MessageType.NEW_PLAYER)
        for link in list(self.links.values()):
            if not link.outgoing:
                self._queue(link, news)
        self.events.append(NetEvent("joined", n, self.table[n]))
        self._reap()
        return n

    # ------------------------------------------------------------------ sending
    def send_state(self, state: P.State) -> None:
        """A state of a tank I run to every other player, by UDP (with a password, each
        copy sealed with the key of that player's link; none goes to a player whose
        link is not up yet)."""
        if self.udp is None:
            return
        self.counters["state_rounds"] += 1
        data = self._pack(state)
        for n, e in self.table.items():
            if n == self.number or e.is_bot:
                continue
            out = data
            if self.password:
                link = self.links.get(n)
                if link is None or link.udp_key is None:
                    self.counters["states_unkeyed"] += 1
                    continue
                out = seal(link.udp_key, data)
            try:
                self.udp.sendto(out, (e.ip, e.udp_port))
            except OSError:
                self.dropped["send_failed"] += 1
                continue
            self.counters["sent"] += 1
            self.counters["states_sent"] += 1
            self.counters["bytes_sent"] += len(out)

    def send_event(self, body: P.Body) -> None:
        """A shot, hit or exit to every linked peer, by TCP."""
        data = self._pack(body)
        for link in list(self.links.values()):
            self._queue(link, data)
        if not isinstance(body, P.Exit):
            self._reap()

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

    def _accept(self) -> None:
        assert self.tcp is not None
        for _ in range(ACCEPTS_PER_POLL):
            try:
                sock, addr = self.tcp.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.dropped["accept_failed"] += 1
                return
            self.dropped.source = addr[0]      # TCP: by address (each connection has its own port)
            if not self._make_room(addr[0]):
                self.dropped["too_many_pending"] += 1
                sock.close()
                continue
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            now = self.clock()
            link = Link(sock, P.StreamReader(self.dropped), Bucket(TCP_RATE, TCP_BURST, now), now, addr=addr,
                        nonce=os.urandom(P.NONCE_SIZE))
            self.pending.append(link)
            self.sel.register(sock, selectors.EVENT_READ, link)
            challenge = P.Challenge(link.nonce, self.password is not None, self.term, self.host_number,
                                    len(self._others()) + (1 if self.number else 0))
            self._queue(link, self._pack_control(challenge))

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

    def _on_pending(self, link: Link, m: P.Message) -> None:
        body = m.body
        now = self.clock()
        ip = link.addr[0]
        if isinstance(body, (P.Join, P.Hello)) and self.password:
            # every answer is checked: a player who proves the password gets in however
            # many wrong guesses an attacker sharing its address made (finding 5); the
            # guesses only earn "too many wrong passwords" once over their budget
            if isinstance(body, P.Join):
                good = join_mac(self.password, link.nonce, body.name)
            else:
                good = hello_mac(self.password, link.nonce, m.sender, body.epoch)
            if not hmac.compare_digest(body.mac, good):
                if not self.auth_failures.take(ip, now):
                    self._refuse(link, P.RefuseCode.RATE, f"too many wrong passwords from {ip}: try again later")
                else:
                    self._refuse(link, P.RefuseCode.PASSWORD, "wrong password")
                return
            link.proven = True
        if isinstance(body, P.Join):
            if self.step_down_to is not None:
                # a newer session goes on there: we are stale, send the joiner on
                self._refuse(link, P.RefuseCode.NOT_HOST, f"{self.step_down_to[0]}:{self.step_down_to[1]}")
                return
            if not self.is_host:
                h = self.table.get(self.host_number)
                self._refuse(link, P.RefuseCode.NOT_HOST, f"{h.ip}:{h.tcp_port}" if h else "")
                return
            if self.probing():
                # alone after losing everyone: maybe left behind by a newer session (terms.py)
                self._refuse(link, P.RefuseCode.RATE, "checking whether the session goes on elsewhere: try again")
                return
            if not self.joins.allow(ip, now):
                # each join makes the host send every member the new table: a flood of
                # joins would fill the members' rate limiters with the host's messages
                self._refuse(link, P.RefuseCode.RATE, f"too many joins from {ip}: try again in a few seconds")
                return
            self._admit(link, m)
        elif isinstance(body, P.Hello):
            link.hello = m
            self._try_hello(link)
        else:
            self.dropped["unexpected"] += 1

    def _try_hello(self, link: Link) -> bool:
        """Bind a HELLO link when the table knows its number with that epoch and the
        address matches; otherwise it waits (the host's NEW_PLAYER may still be on
        its way) until HELLO_WAIT."""
        m = link.hello
        assert m is not None
        n = m.sender
        e = self.table.get(n)
        if e is None or e.epoch != m.body.epoch:
            epoch = m.body.epoch
            if (n, epoch) in self.departed:
                self._refuse(link, P.RefuseCode.BAD_REQUEST, "you left the session")
            elif self.is_host or epoch <= self.max_epoch:
                # the host knows every number it gave, and epochs only grow: this HELLO
                # is for no player that is or will be (finding 5: parked HELLOs)
                self.dropped["unknown"] += 1
                self._refuse(link, P.RefuseCode.BAD_REQUEST, f"no player {n} with epoch {epoch} here")
            else:
                waiting = [k for k in self.pending if k.hello is not None and not k.closing]
                if len(waiting) > MAX_HELLO_WAITING:
                    # a real joiner's HELLO waits a round trip at most: the oldest goes
                    self._refuse(min(waiting, key=lambda k: (k.proven, k.opened)), P.RefuseCode.BAD_REQUEST,
                                 "no such player yet")
            return False
        try:
            ip = link.sock.getpeername()[0]
        except OSError:
            self._drop_link(link, "closed")
            return False
        mine = self.links.get(n)
        if mine is not None and mine.initiated and n > self.number and ip == e.ip:
            # both opened a link at once: the one opened by the higher number stays
            mine.refused = True
            self._close_link(mine)
        elif n == self.number or n in self.links or (ip != e.ip and e.ip != "0.0.0.0"):
            self.dropped["impostor"] += 1
            self._refuse(link, P.RefuseCode.BAD_REQUEST, f"player {n} is already linked")
            return False
        self.pending.remove(link)
        if self.password:
            link.udp_key = datagram_key(self.password, m.body.mac)
        self.window.anchor(n, m.seq, self.clock())
        self._bind_link(link, n, registered=True)
        return True

    def _admit(self, link: Link, m: P.Message) -> None:
        join: P.Join = m.body
        if not hmac.compare_digest(join.digest, self.digest):
            what = f" ({self.label})" if self.label else ""
            self._refuse(link, P.RefuseCode.MISMATCH,
                         f"your arena or vehicle differs from the host's{what}: their hashes do not match")
            return
        problem = name_problem(join.name, [e.name for e in self.table.values()])
        if problem is not None:
            self._refuse(link, P.RefuseCode.NAME, problem)
            return
        slot = self._new_slot()
        if slot is None:
            self._refuse(link, P.RefuseCode.FULL, f"session full: {P.MAX_PLAYERS} players already")
            return
        try:
            ip = link.sock.getpeername()[0]
        except OSError:
            self._drop_link(link, "closed")
            return
        n, epoch = slot
        self.table[n] = P.Entry(n, epoch, ip, join.tcp_port, join.udp_port, join.name)
        self._saw(self.table[n])
        self.pending.remove(link)
        if self.password:
            link.udp_key = datagram_key(self.password, join.mac)
        self.window.anchor(n, m.seq, self.clock())
        self._bind_link(link, n, registered=True)
        table = self._table()
        t = self.session_time()
        self._queue(link, self._pack(P.Assign(n, t, table, self.term), P.MessageType.NUMBER))
        news = self._pack(P.Assign(n, t, table, self.term), P.MessageType.NEW_PLAYER)
        for k, other in list(self.links.items()):
            if k != n:
                self._queue(other, news)
        self.events.append(NetEvent("joined", n, self.table[n]))

    def _refuse(self, link: Link, code: P.RefuseCode, text: str) -> None:
        self.dropped[f"refused_{code.name.lower()}"] += 1
        self._queue(link, self._pack_control(P.Refuse(code, text)))
        link.closing = True
        link.hello = None
        self._flush(link)

    def _table(self) -> P.Table:
        return P.Table(self.host_number, tuple(self.table[n] for n in sorted(self.table)))

    def _merge_table(self, table: P.Table, new: int) -> None:
        """The host's table: add who we do not know (unless we saw them leave)."""
        for e in table.entries:
            self.max_epoch = max(self.max_epoch, e.epoch)
            if (e.number, e.epoch) in self.departed or e.number == self.number:
                continue
            old = self.table.get(e.number)
            if old is not None and old.epoch == e.epoch and old.owner != e.owner:
                self.table[e.number] = e           # a computer opponent changed hands
                self.addr_buckets.clear()
                if e.owner == self.number:
                    self.events.append(NetEvent("adopt", e.number, e))
                continue
            if old is None or old.epoch != e.epoch:
                if old is not None:
                    self._remove(e.number, "replaced")
                self.table[e.number] = e
                self._saw(e)
                self.last_heard[e.number] = self.clock()
                self.events.append(NetEvent("joined", e.number, e))
        for link in list(self.pending):
            if link.hello is not None:
                self._try_hello(link)

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

    def _read_udp(self) -> None:
        assert self.udp is not None
        now = self.clock()
        for _ in range(UDP_READS):    # bounded: a flood cannot starve the game loop
            try:
                data, addr = self.udp.recvfrom(2048)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.dropped["udp_error"] += 1
                return
            self.counters["bytes_received"] += len(data)
            self.dropped.source = addr
            if not self._udp_budget(addr, now):
                # a member over what its tanks may send: dropped before any tag or decode,
                # so its flood costs a dictionary look-up, not the others' states (finding 8)
                self.dropped["flood"] += 1
                continue
            if self.password:
                data = self._unseal(data, addr)
                if data is None:
                    continue
            m = P.decode(data, self.dropped)
            if m is None:
                continue
            if self._from_member(m.sender, addr) is None:
                continue
            if not isinstance(m.body, P.State):
                self.dropped["unexpected"] += 1
                continue
            if self._on_state(m, now):
                self.counters["received"] += 1
                self.last_heard[m.sender] = now

    def _udp_budget(self, addr: tuple, now: float) -> bool:
        """Whether a datagram from ``addr`` may be read: a member's address gets the
        per-tank rate times the tanks it runs (the host's includes its computer
        opponents); an address not in the table is read (and counted) as before."""
        b = self.addr_buckets.get(addr)
        if b is None:
            tanks = sum(1 for e in self.table.values() if (e.ip, e.udp_port) == addr)
            if tanks == 0:
                return True
            b = self.addr_buckets[addr] = Bucket(UDP_RATE * tanks, UDP_BURST * tanks, now)
        return b.take(now)

    def _from_member(self, sender: int, addr: tuple) -> P.Entry | None:
        """The table entry of a datagram's sender if it came from that player's address;
        otherwise None, counted as ``impostor`` (a known number) or ``unknown``."""
        e = self.table.get(sender)
        if e is None or e.is_bot or sender == self.number or addr != (e.ip, e.udp_port):
            self.dropped["impostor" if e is not None else "unknown"] += 1
            return None
        return e

    def _unseal(self, data: bytes, addr: tuple) -> bytes | None:
        """A password session's datagram without its tag, once the tag checks out with
        the key of its sender's link; None (counted) for anything else."""
        if len(data) < P.HEADER.size + TAG_SIZE:
            self.dropped["short"] += 1
            return None
        sender = data[4]                      # the header's sender byte
        if self._from_member(sender, addr) is None:
            return None
        link = self.links.get(sender)
        if link is None or link.udp_key is None:
            self.dropped["no_key"] += 1
            return None
        message = unseal(link.udp_key, data)
        if message is None:
            self.dropped["bad_mac"] += 1
        return message

    def _on_state(self, m: P.Message, now: float) -> bool:
        """Take a state (from UDP or TCP) if its sender runs that tank, its sequence
        number is within the window and newer than the last of that tank, and the
        tank is within its rate; True when taken."""
        if not self._may_speak(m.sender, m.body.tank) or m.body.tank == self.number:
            self.dropped["impostor"] += 1
            return False
        within = self.window.admits(m.sender, m.seq, now)
        if not within:
            self.dropped["no_anchor" if within is None else "window"] += 1
            return False
        key = (m.sender, m.body.tank)
        if m.seq <= self.last_state_seq.get(key, -1):
            self.dropped["stale"] += 1        # latest sequence wins
            return False
        if not self.state_buckets.take(key, now):
            self.dropped["rate"] += 1
            return False
        self.last_state_seq[key] = m.seq
        self.window.anchor(m.sender, m.seq, now)
        self.counters["states_received"] += 1
        self.states_from[m.sender] += 1
        self.latencies.append(P.age(now, m.timestamp))
        self.events.append(NetEvent("state", m.sender, m.body))
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

    def kick(self, n: int, reason: str) -> None:
        """The host disconnects player ``n``: a refusal saying why, then it leaves
        every table (TABLE), and its (number, epoch) is never let back in."""
        if not self.is_host or n == self.number or n not in self.table:
            return
        link = self.links.pop(n, None)
        if link is not None:
            self._queue(link, self._pack(P.Refuse(P.RefuseCode.BAD_REQUEST, reason)))
            self._flush(link)
            try:
                self.sel.unregister(link.sock)
            except (KeyError, ValueError):
                pass
            # half-close and hold the socket a moment: closing it with the peer's unread
            # messages in our buffer would reset the connection and lose the refusal
            try:
                link.sock.shutdown(socket.SHUT_WR)
            except OSError:
                pass
            self._linger.append((link.sock, self.clock() + 1.0))
        self._remove(n, "disconnected: " + reason)
        self._reap()

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


def percentile(values: list[float], q: float) -> float:
    """The q-th percentile (0..100) by nearest rank; NaN for no values."""
    if not values:
        return math.nan
    s = sorted(values)
    k = min(len(s) - 1, max(0, int(math.ceil(q / 100.0 * len(s))) - 1))
    return s[k]
