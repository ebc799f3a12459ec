"""The joiner's side of the protocol: the join request on a connection the transport
opened (answering the challenge, reading the host's NUMBER, a refusal, a redirect or
"busy"), and the mesh links a joiner opens.  No I/O: part of
:class:`~tanktool.net.core.Core`; :meth:`~tanktool.net.peer.Peer.join` dials, waits and
retries."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import NetError
from . import protocol as P
from .auth import datagram_key, join_mac
from .links import Connect, Link, parse_address
from .names import visible


@dataclass(frozen=True)
class JoinOutcome:
    """How a join request ended: ``joined``, ``busy`` (the host said "too many joins":
    ask again soon), ``redirect`` (to ``address``, the host) or ``error`` (``text``
    says why, one line)."""

    kind: str
    text: str = ""
    address: tuple[str, int] | None = None


class JoinerMixin:
    """Joining, from the core's side."""

    def joining(self, addr: tuple[str, int], tcp_port: int, udp_port: int, now: float) -> int:
        """The transport opened a connection to ``addr`` to join the session there; this
        peer listens on ``tcp_port`` / ``udp_port``.  Returns the link's number; the
        outcome is in :attr:`join_outcome` once the other end has answered."""
        self.now = now
        self.join_outcome = None
        self.join_ports = (tcp_port, udp_port)
        link = self._new_link(tuple(addr), joining=True)
        return link.id

    def _join_failed(self, link: Link, reason: str) -> None:
        where = f"{link.addr[0]}:{link.addr[1]}"
        text = {"closed": f"{where} closed the connection",
                "garbage": f"{where} sent something that is not a tanktool message"}.get(reason, f"{where}: {reason}")
        self._join_error(link, text)

    def _join_error(self, link: Link, text: str) -> None:
        self._close_link(link, "join failed")
        if self.join_outcome is None:
            self.join_outcome = JoinOutcome("error", text)

    def _on_join_answer(self, link: Link, m: P.Message) -> None:
        where = f"{link.addr[0]}:{link.addr[1]}"
        if link.join_sent is None:              # its challenge
            if not isinstance(m.body, P.Challenge):
                self._join_error(link, f"{where} did not answer like a tanktool peer")
                return
            if m.body.password and not self.password:
                self._join_error(link, f"{where} wants a password (--password)")
                return
            link.join_mac = join_mac(self.password, m.body.nonce, self.name) if self.password else bytes(P.MAC_SIZE)
            link.join_sent = self.now
            tcp_port, udp_port = self.join_ports
            self._queue(link, self._pack(P.Join(self.name, tcp_port, udp_port, link.join_mac, self.digest)))
            return
        if isinstance(m.body, P.Refuse):
            self._close_link(link, "refused")
            text = visible(m.body.text)
            if m.body.code == P.RefuseCode.RATE:
                self.join_outcome = JoinOutcome("busy", f"join refused by {where}: {text}")
            elif m.body.code == P.RefuseCode.NOT_HOST:
                try:
                    self.join_outcome = JoinOutcome("redirect", address=parse_address(text, need_host=True))
                except NetError:
                    self.join_outcome = JoinOutcome("error", f"{where} is not the host and did not say who is")
            else:
                self.join_outcome = JoinOutcome("error", f"join refused by {where}: {text}")
            return
        if m.type != P.MessageType.NUMBER or m.sender != m.body.table.host:
            self._join_error(link, f"{where} did not answer the join request")
            return
        self._joined(link, m)

    def _joined(self, link: Link, m: P.Message) -> None:
        """The host's NUMBER: our number, the table, the term, the session clock."""
        body: P.Assign = m.body
        now = self.now
        self.number = body.number
        self.host_number = body.table.host
        self.term = body.term
        # the session clock: the host's, plus half the round trip
        assert link.join_sent is not None
        self.session_offset = now - (body.session_t + 0.5 * (now - link.join_sent))
        for e in body.table.entries:
            if e.number == self.host_number and e.ip == "0.0.0.0":
                e = P.Entry(e.number, e.epoch, link.addr[0], e.tcp_port, e.udp_port, e.name)   # reach it as dialled
            self.table[e.number] = e
            self._saw(e)
        link.joining = False
        if self.password:
            link.udp_key = datagram_key(self.password, link.join_mac)
        self.window.anchor(self.host_number, m.seq, now)
        self._bind_link(link, self.host_number)
        self.join_outcome = JoinOutcome("joined")
        # the joiner links to those in the table it was given; who joins after it (a
        # NEW_PLAYER maybe in the same read) links to it
        for e in [e for n, e in sorted(self.table.items())
                  if n not in (self.number, self.host_number) and not e.is_bot]:
            if e.number in self.table and e.number not in self.links:
                self._link_to(e)
        for pending in list(self.pending):          # a member's HELLO that came first
            if pending.hello is not None:
                self._try_hello(pending)
        self._take_probe_list(body.lost)

    def _link_to(self, e: P.Entry) -> None:
        """Open the mesh link to a table member (the joiner opens them all).  The link is
        bound to ``e.number`` at once (we dialled the address the host's table gives for
        it) and answers the member's challenge with a HELLO when it comes."""
        link = self._new_link((e.ip, e.tcp_port), outgoing=True, initiated=True)
        self._bind_link(link, e.number)
        self.actions.append(Connect(link.id, (e.ip, e.tcp_port)))
