"""The joiner's side: listening, the join handshake with its redirects and "busy"
answers, and the mesh links a joiner opens.  Part of :class:`~tanktool.net.peer.Peer`."""

from __future__ import annotations

import errno
import selectors
import socket
import time

from ..errors import NetError
from . import protocol as P
from .auth import datagram_key, join_mac
from .guard import Bucket
from .limits import LISTEN_BACKLOG, TCP_RATE, TCP_BURST, JOIN_BUSY_WAIT
from .links import Link, _Busy, parse_address
from .names import visible


class JoinerMixin:
    """Listening and joining."""

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

    def _send_blocking(self, sock: socket.socket, body: P.Body) -> None:
        data = self._pack(body)
        sock.sendall(data)
        self.counters["sent"] += 1
        self.counters["bytes_sent"] += len(data)
