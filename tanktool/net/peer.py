"""A peer of a network session on real sockets: the thin transport around the protocol
core (:mod:`.core`).

:class:`Peer` owns the TCP listener, the UDP socket, the connections and a selector; it
feeds the core what arrives (with the time of its clock) and performs the core's actions
(send, send a datagram, close, connect).  Everything the protocol decides — the player
table, joins, numbers and epochs, terms and host migration, silences, kicks, which
states are taken — is the core's; the peer's attributes that are not its own (``table``,
``links``, ``dropped``, ``term`` ...) are read through to the core.

A connection is flushed as the kernel takes it; one whose unsent data passes
``MAX_OUTBUF`` is too slow and is dropped.
"""

from __future__ import annotations

import errno
import selectors
import socket
import time
from dataclasses import dataclass, field
from typing import Any, Callable

from ..errors import NetError
from . import limits as L
from . import protocol as P
from .auth import hello_mac, join_mac  # noqa: F401 (re-exported)
from .core import Core
from .guard import Bucket  # noqa: F401 (re-exported)
from .limits import (  # noqa: F401 - re-exported for those who read them
    SILENCE, PENDING_TIMEOUT, HELLO_WAIT, MAX_HELLO_WAITING, MAX_PENDING, MAX_PENDING_PER_IP,
    ACCEPTS_PER_POLL, LISTEN_BACKLOG, TCP_RATE, TCP_BURST, UDP_RATE, UDP_BURST, UDP_READS,
    JOIN_RATE, JOIN_BURST, JOINS_RATE, JOINS_BURST, AUTH_FAIL_RATE, AUTH_FAIL_BURST, JOIN_SETTLE,
    JOIN_BUSY_WAIT, MAX_OUTBUF, LATENCY_SAMPLES,
)
from .links import Close, Connect, Link, NetEvent, Send, SendTo, parse_address, percentile  # noqa: F401

__all__ = ["Peer", "NetEvent", "Link", "Bucket", "parse_address", "free_port", "join_mac", "hello_mac",
           "percentile"]


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


@dataclass
class _Conn:
    """A TCP connection of the transport, and the core's link number for it."""

    sock: socket.socket
    link: int
    out: bytearray = field(default_factory=bytearray)
    close_at: float | None = None     # closing: flushed, then closed by this time (monotonic)
    linger: float = 0.0               # after the flush: half-close and keep this long


class Peer:
    """One player's end of a session.  Build with :meth:`host` or :meth:`join`, then
    call :meth:`poll` often (it never blocks longer than its timeout)."""

    def __init__(self, name: str, password: str | None = None, clock: Callable[[], float] = time.time,
                 silence: float = SILENCE, digest: bytes = bytes(P.DIGEST_SIZE), label: str = "") -> None:
        self.clock = clock
        self.core = Core(name, password, silence=silence, digest=digest, label=label, now=clock())
        self.sel = selectors.DefaultSelector()
        self.tcp: socket.socket | None = None
        self.udp: socket.socket | None = None
        self.conns: dict[int, _Conn] = {}          # by link number
        self._closing: list[_Conn] = []            # closed by the core, still flushing or lingering
        self._shut = False                         # sockets closed

    #: the transport's own attributes; every other one is the core's
    _OWN = frozenset({"clock", "core", "sel", "tcp", "udp", "conns", "_closing", "_shut"})

    def __getattr__(self, name: str) -> Any:
        # the protocol's state (table, links, pending, dropped, term, ...) is the core's
        if name == "core":
            raise AttributeError(name)
        return getattr(self.core, name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name in self._OWN:
            object.__setattr__(self, name, value)
        else:
            setattr(self.core, name, value)

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
        peer.core.start_host((ip, tcp_port, peer.udp_address[1]), peer.clock())
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

    def _join_loop(self, address: tuple[str, int], timeout: float, port: int, busy_until: float) -> None:
        """Ask ``address`` to join, following redirects and waiting out "busy"."""
        redirects = 0
        while True:
            outcome = self._join_once(address, timeout, port)
            if outcome.kind == "busy":
                if time.monotonic() + JOIN_BUSY_WAIT > busy_until:
                    raise NetError(outcome.text)
                time.sleep(JOIN_BUSY_WAIT)
                continue
            if outcome.kind == "error":
                raise NetError(outcome.text)
            if outcome.kind == "joined":
                return
            assert outcome.address is not None
            redirects += 1       # a member that is not the host names it: follow
            if redirects >= 3:
                raise NetError(f"cannot join: redirected too many times (last {outcome.address[0]}:"
                               f"{outcome.address[1]})")
            address = outcome.address

    def _join_once(self, address: tuple[str, int], timeout: float, port: int) -> Any:
        """One join request: dial, listen on the interface that reached the host, and
        serve everything until the core has the outcome (or the time is up)."""
        where = f"{address[0]}:{address[1]}"
        try:
            sock = socket.create_connection(address, timeout=timeout)
        except OSError as e:
            raise NetError(f"cannot reach {where}: {e.strerror or e}") from None
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        if self.tcp is None:
            try:
                self._listen(sock.getsockname()[0], port)
            except BaseException:
                sock.close()
                raise
        sock.setblocking(False)
        link = self.core.joining(address, self.tcp_address[1], self.udp_address[1], self.clock())
        self._adopt(sock, link)
        deadline = time.monotonic() + timeout
        while self.core.join_outcome is None:
            left = deadline - time.monotonic()
            if left <= 0:
                self.core.disconnected(link, "timeout", self.clock())
                self._perform()
                raise NetError(f"{where} did not answer in time")
            self._service(min(left, 0.05))
        return self.core.join_outcome

    def _settle(self, seconds: float) -> None:
        """Poll until every mesh link this joiner opened has had its challenge answered
        (or failed), for at most ``seconds``; what happened waits for the next poll."""
        end = time.monotonic() + seconds
        while any(link.outgoing for link in self.core.links.values()):
            left = end - time.monotonic()
            if left <= 0:
                break
            self._service(min(left, 0.01))

    def rejoin(self, address: tuple[str, int] | None = None, timeout: float = 5.0) -> None:
        """Leave what is left of our session (our computer opponents with it) and join
        the one at ``address`` (default: where a probe found a newer session) as a new
        member, on the same ports.  Blocks like ``Peer.join``.  If it fails (that session's
        peer went away on the way), we host our own session again on our ports, still
        probing the players we lost, and NetError says why."""
        address = address or self.core.step_down_to
        if address is None:
            raise NetError("no session to rejoin")
        self.core.forget_session(self.clock())
        self._perform()
        try:
            self._join_loop(address, timeout, 0, time.monotonic() + timeout)
        except NetError:
            ip, tcp_port = self.tcp_address
            self.core.host_alone((ip, tcp_port, self.udp_address[1]), self.clock())
            self._perform()
            raise
        self._settle(1.0)

    # ------------------------------------------------------------------ the game's calls
    def session_time(self) -> float:
        return self.clock() - self.core.session_offset

    def send_state(self, state: P.State) -> None:
        """A state of a tank I run to every other player, by UDP."""
        if self.udp is None:
            return
        self.core.send_state(state, self.clock())
        self._perform()

    def send_event(self, body: P.Body) -> None:
        """A shot, hit or exit to every linked peer, by TCP."""
        self.core.send_event(body, self.clock())
        self._perform()

    def add_bot(self, name: str) -> int | None:
        """The host adds a computer opponent (it runs it): its number, or None when full."""
        n = self.core.add_bot(name, self.clock())
        self._perform()
        return n

    def kick(self, n: int, reason: str) -> None:
        """The host disconnects player ``n`` with a reason."""
        self.core.kick(n, reason, self.clock())
        self._perform()

    # ------------------------------------------------------------------ the loop
    def poll(self, timeout: float = 0.0) -> list[NetEvent]:
        """Handle everything that arrived (waiting at most ``timeout`` seconds for the
        first thing), run the core's timers; return what happened."""
        if self.closed:
            return []
        self._service(timeout)
        return self.core.take_events()

    @property
    def closed(self) -> bool:
        return self.core.closed

    def _service(self, timeout: float) -> None:
        self._perform()            # what a direct call on the core (tests) left to do
        accept = False
        for key, mask in self.sel.select(max(timeout, 0.0)):
            if key.data == "accept":
                accept = True
            elif key.data == "udp":
                self._read_udp()
            else:
                conn: _Conn = key.data
                if conn.sock.fileno() < 0:
                    continue
                if mask & selectors.EVENT_WRITE:
                    self._flush(conn)
                if mask & selectors.EVENT_READ and conn.sock.fileno() >= 0 and conn.close_at is None:
                    self._read_tcp(conn)
            self._perform()
        # new connections last: one accepted at the previous poll has had its answer read
        # before any newer one can push it out of the pending list
        if accept:
            self._accept()
        self.core.tick(self.clock())
        self._perform()
        self._linger_tick()
        if self.core.closed:          # the core left (kicked): so do the sockets
            self.close(send_exit=False)

    def _accept(self) -> None:
        assert self.tcp is not None
        for _ in range(ACCEPTS_PER_POLL):
            try:
                sock, addr = self.tcp.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.core.dropped["accept_failed"] += 1
                return
            link = self.core.accepted(addr, self.clock())
            if link is None:
                sock.close()
            else:
                sock.setblocking(False)
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                self._adopt(sock, link)
            self._perform()

    def _adopt(self, sock: socket.socket, link: int) -> None:
        conn = self.conns[link] = _Conn(sock, link)
        self.sel.register(sock, selectors.EVENT_READ, conn)

    def _read_tcp(self, conn: _Conn) -> None:
        try:
            data = conn.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        self.core.received(conn.link, data, self.clock())

    def _read_udp(self) -> None:
        assert self.udp is not None
        datagram = self.core.datagram
        for _ in range(UDP_READS):    # bounded: a flood cannot starve the game loop
            try:
                data, addr = self.udp.recvfrom(2048)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.core.dropped["udp_error"] += 1
                return
            datagram(addr, data, self.clock())

    # ------------------------------------------------------------------ performing actions
    def _perform(self) -> None:
        """Do what the core asked, in order; what fails is told back to the core (after
        the handler that asked is done: a failure never pulls a player out of the table
        while the core is using it, the KeyError of finding 2)."""
        while True:
            actions = self.core.take_actions()
            if not actions:
                return
            for a in actions:
                if isinstance(a, SendTo):
                    self._sendto(a)
                elif isinstance(a, Send):
                    conn = self.conns.get(a.link)
                    if conn is not None and conn.close_at is None:
                        conn.out += a.data
                        self._flush(conn)
                elif isinstance(a, Close):
                    self._close(a)
                elif isinstance(a, Connect):
                    self._connect(a)

    def _sendto(self, a: SendTo) -> None:
        assert self.udp is not None
        try:
            self.udp.sendto(a.data, a.addr)
        except OSError:
            self.core.unsent(a.data)

    def _connect(self, a: Connect) -> None:
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        err = sock.connect_ex(a.addr)
        if err not in (0, errno.EINPROGRESS, errno.EWOULDBLOCK, errno.EAGAIN):
            sock.close()
            self.core.disconnected(a.link, "connect failed", self.clock())
            return
        self._adopt(sock, a.link)

    def _flush(self, conn: _Conn) -> None:
        if conn.out:
            try:
                n = conn.sock.send(conn.out)
                del conn.out[:n]
            except (BlockingIOError, InterruptedError):
                pass
            except OSError:
                self._gone(conn, "closed")
                return
        if len(conn.out) > MAX_OUTBUF:
            self._gone(conn, "too slow")
            return
        if conn.close_at is not None and not conn.out:
            self._finish(conn)
            return
        # closing: only the flush is waited for (what it still says is never read, so a
        # readable socket must not wake every select until its deadline)
        want = selectors.EVENT_WRITE if conn.close_at is not None else \
            selectors.EVENT_READ | (selectors.EVENT_WRITE if conn.out else 0)
        try:
            if self.sel.get_key(conn.sock).events != want:
                self.sel.modify(conn.sock, want, conn)
        except (KeyError, ValueError):
            pass

    def _gone(self, conn: _Conn, reason: str) -> None:
        """A connection failed: closed here, and the core told."""
        conn.out.clear()
        self._release(conn)
        if self.conns.pop(conn.link, None) is not None:
            self.core.disconnected(conn.link, reason, self.clock())

    def _close(self, a: Close) -> None:
        """The core closed a link: flush what it sent, then close (or half-close and
        linger)."""
        conn = self.conns.pop(a.link, None)
        if conn is None:
            return
        conn.close_at = time.monotonic() + max(a.linger, 1.0)
        conn.linger = a.linger
        self._closing.append(conn)
        self._flush(conn)

    def _finish(self, conn: _Conn) -> None:
        """A closing connection is flushed: close it, or half-close it and let it linger."""
        if conn.linger > 0:
            try:
                self.sel.unregister(conn.sock)
            except (KeyError, ValueError):
                pass
            try:
                conn.sock.shutdown(socket.SHUT_WR)
            except OSError:
                pass
            conn.close_at = time.monotonic() + conn.linger
            conn.linger = 0.0
            return
        self._release(conn)

    def _release(self, conn: _Conn) -> None:
        try:
            self.sel.unregister(conn.sock)
        except (KeyError, ValueError):
            pass
        conn.sock.close()
        if conn in self._closing:
            self._closing.remove(conn)

    def _linger_tick(self) -> None:
        now = time.monotonic()
        for conn in list(self._closing):
            if conn.close_at is not None and conn.close_at <= now:
                self._release(conn)

    # ------------------------------------------------------------------ leaving
    def close(self, send_exit: bool = True) -> None:
        """Leave: tell everyone (TCP), close every socket."""
        if self._shut:
            return
        self._shut = True
        self.core.leave(self.clock(), send_exit)
        for a in self.core.take_actions():
            conn = self.conns.get(getattr(a, "link", -1))
            if isinstance(a, Send) and conn is not None:
                conn.out += a.data
        for conn in list(self.conns.values()):
            if conn.out:       # the goodbyes: up to 0.5 s a link
                try:
                    conn.sock.setblocking(True)
                    conn.sock.settimeout(0.5)
                    conn.sock.sendall(conn.out)
                except OSError:
                    pass
        for conn in list(self.conns.values()) + list(self._closing):
            self._release(conn)
        self.conns.clear()
        for s in (self.tcp, self.udp):
            if s is not None:
                try:
                    self.sel.unregister(s)
                except (KeyError, ValueError):
                    pass
                s.close()
        self.sel.close()
