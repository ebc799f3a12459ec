"""Protocol cores (:mod:`.core`) on a simulated network (:mod:`.simnet`): the transport
of :class:`~tanktool.net.peer.Peer` without sockets, for deterministic tests of joins,
leaves, host migration, partitions, pauses, floods and cheats.

Each node has an address ``10.0.0.k`` (TCP and UDP port 5000) and a core.  Every
``step`` (10 ms) each running node's core ticks and, at ``state_hz``, sends a state for
every tank it speaks for (:attr:`SimCluster.states` makes them; by default a tank
driving a slow circle).  Connections are reliable and ordered; datagrams go through the
:class:`~tanktool.net.simnet.SimNet` (loss, jitter, reordering, partitions).  A paused
node reads nothing until resumed (what arrived waits, as in a socket buffer); a killed
node's connections close.  :meth:`SimCluster.dial` and :meth:`SimCluster.inject` give an
attacker raw connections and datagrams.
"""

from __future__ import annotations

import heapq
import math
import random
from dataclasses import dataclass, field
from typing import Any, Callable

from . import protocol as P
from .core import Core
from .limits import JOIN_BUSY_WAIT
from .links import Close, Connect, NetEvent, Send, SendTo
from .simnet import SimNet

PORT = 5000


@dataclass
class SimNode:
    """A simulated process running one core."""

    name: str
    ip: str
    core: Core
    listening: bool = False
    paused: bool = False
    dead: bool = False
    inbox: list[tuple] = field(default_factory=list)        # what arrived while paused
    events: list[tuple[float, NetEvent]] = field(default_factory=list)
    join_to: tuple[str, int] | None = None                  # joining through this address
    join_at: float | None = None                            # (again) at this time
    join_error: str = ""
    next_state: float = 0.0
    rejoining: bool = False                                 # a failed join hosts alone again

    @property
    def address(self) -> tuple[str, int]:
        return (self.ip, PORT)


@dataclass
class RawConn:
    """An attacker's connection: what it received, and whether it was closed."""

    cluster: "SimCluster"
    conn: int
    received: bytearray = field(default_factory=bytearray)
    closed: bool = False

    def send(self, data: bytes) -> None:
        self.cluster._stream(self.conn, 0, "data", data)

    def messages(self) -> list[P.Message]:
        return P.StreamReader({}).feed(bytes(self.received))


@dataclass
class _Conn:
    """A connection: end 0 dialled, end 1 accepted; per end (node or None for a raw
    attacker end, link number)."""

    ends: list[tuple[Any, int]]
    last: list[float] = field(default_factory=lambda: [0.0, 0.0])   # last arrival each way (order)
    open: list[bool] = field(default_factory=lambda: [True, True])


class SimCluster:
    """Several cores on one simulated network and clock (see the module docstring)."""

    def __init__(self, seed: int = 0, delay: float = 0.0, jitter: float = 0.0, loss: float = 0.0,
                 reorder: float = 0.0, step: float = 0.01, state_hz: float = 30.0) -> None:
        self.udp = SimNet(seed=seed, delay=delay, jitter=jitter, loss=loss, reorder=reorder)
        self.rng = random.Random(seed + 1)
        self.step, self.state_hz = step, state_hz
        self.nodes: dict[str, SimNode] = {}
        self.conns: dict[int, _Conn] = {}
        self._heap: list[tuple[float, int, int, int, str, bytes]] = []   # at, order, conn, to end, kind, data
        self._order = 0
        #: the state a node sends for tank ``n`` at session time ``t`` (node, n, t) -> State
        self.states: Callable[[SimNode, int, float], P.State] = circle_state
        #: called with (node, events) after each node's turn (a game's reaction)
        self.on_events: Callable[[SimNode, list[NetEvent]], None] | None = None
        #: a node that stepped down rejoins the newer session at once, as a game does
        self.auto_rejoin = True
        #: called at the start of every step (a game world moving on), with the time
        self.on_step: Callable[[float], None] | None = None

    @property
    def now(self) -> float:
        return self.udp.now

    # ------------------------------------------------------------------ nodes
    def node(self, name: str, password: str | None = None, **kw: Any) -> SimNode:
        ip = f"10.0.0.{len(self.nodes) + 1}"
        core = Core(name, password, now=self.now, nonce_source=lambda k: self.rng.randbytes(k), **kw)
        node = self.nodes[ip] = SimNode(name, ip, core, next_state=self.now)
        return node

    def host(self, name: str, password: str | None = None, **kw: Any) -> SimNode:
        node = self.node(name, password, **kw)
        node.listening = True
        node.core.start_host((node.ip, PORT, PORT), self.now)
        return node

    def join(self, name: str, via: SimNode | tuple[str, int], password: str | None = None, settle: float = 1.0,
             **kw: Any) -> SimNode:
        """A new node that joins through ``via``; runs the network ``settle`` seconds."""
        node = self.node(name, password, **kw)
        self.start_join(node, via)
        self.run(settle)
        return node

    def start_join(self, node: SimNode, via: SimNode | tuple[str, int]) -> None:
        node.listening = True
        node.join_to = via.address if isinstance(via, SimNode) else via
        node.join_at = self.now
        node.join_error = ""

    def pause(self, node: SimNode) -> None:
        node.paused = True

    def resume(self, node: SimNode) -> None:
        node.paused = False
        inbox, node.inbox = node.inbox, []
        for item in inbox:
            self._deliver_to(node, item)
        self._perform(node)

    def leave(self, node: SimNode) -> None:
        """The player quits (EXIT to everyone, links closed)."""
        node.core.leave(self.now)
        self._perform(node)
        node.listening = False

    def kill(self, node: SimNode) -> None:
        """SIGKILL: no goodbye; the system closes its connections."""
        node.dead, node.listening = True, False
        for cid, c in self.conns.items():
            for k in (0, 1):
                if c.ends[k][0] is node and c.open[k]:
                    self._stream(cid, k, "fin", b"")

    def rejoin(self, node: SimNode) -> None:
        """A node that stepped down joins the session its probe found."""
        assert node.core.step_down_to is not None
        to = node.core.step_down_to
        node.core.forget_session(self.now)
        self._perform(node)
        self.start_join(node, to)
        node.rejoining = True

    # ------------------------------------------------------------------ attackers
    def dial(self, from_ip: str, to: SimNode) -> RawConn:
        """A raw connection from ``from_ip`` to ``to``'s listener."""
        cid = self._connect((None, 0), to.address, from_ip)
        raw = RawConn(self, cid)
        self.conns[cid].ends[0] = (raw, 0)
        return raw

    def inject(self, src: tuple[str, int], dst: SimNode, data: bytes) -> None:
        """A datagram from ``src`` (forged or not) to ``dst``."""
        self.udp.send(src[0], dst.ip, (src, data))

    # ------------------------------------------------------------------ running
    def run(self, seconds: float) -> None:
        end = self.now + seconds - 1e-9
        while self.now < end:
            self.udp.advance(self.step)
            if self.on_step is not None:
                self.on_step(self.now)
            self._deliver()
            for node in list(self.nodes.values()):
                if not node.paused and not node.dead:
                    self._turn(node)

    def _turn(self, node: SimNode) -> None:
        core, now = node.core, self.now
        if node.join_at is not None and now >= node.join_at:
            node.join_at = None
            assert node.join_to is not None
            self._dial_join(node, node.join_to)
        outcome = core.join_outcome
        if outcome is not None and outcome.kind != "joined" and node.join_to is not None and node.join_at is None:
            core.join_outcome = None
            if outcome.kind == "busy":
                node.join_at = now + JOIN_BUSY_WAIT
            elif outcome.kind == "redirect":
                node.join_to, node.join_at = outcome.address, now
            else:
                node.join_error, node.join_to = outcome.text, None
                if node.rejoining:                   # as Peer.rejoin does
                    core.host_alone((node.ip, PORT, PORT), now)
        if outcome is not None and outcome.kind in ("joined", "error"):
            node.rejoining = False
        core.tick(now)
        if core.number and now >= node.next_state and not core.closed:
            node.next_state = max(node.next_state + 1.0 / self.state_hz, now - 1.0 / self.state_hz)
            for n in core.speaks_for():
                core.send_state(self.states(node, n, core.session_time()), now)
        self._perform(node)
        events = core.take_events()
        node.events += [(now, e) for e in events]
        if self.on_events is not None and events:
            self.on_events(node, events)
            self._perform(node)
        if self.auto_rejoin and core.step_down_to is not None:
            self.rejoin(node)

    def _dial_join(self, node: SimNode, addr: tuple[str, int]) -> None:
        link = node.core.joining(addr, PORT, PORT, self.now)
        cid = self._connect((node, link), addr, node.ip)
        if cid < 0:
            node.core.disconnected(link, "closed", self.now)
        self._perform(node)

    def _perform(self, node: SimNode) -> None:
        for a in node.core.take_actions():
            if isinstance(a, SendTo):
                self.udp.send(node.ip, a.addr[0], ((node.ip, PORT), a.data))
            elif isinstance(a, Send):
                cid, end = self._find(node, a.link)
                if cid is not None:
                    self._stream(cid, end, "data", a.data)
            elif isinstance(a, Close):
                cid, end = self._find(node, a.link)
                if cid is not None:
                    self._stream(cid, end, "fin", b"")
            elif isinstance(a, Connect):
                if self._connect((node, a.link), a.addr, node.ip) < 0:
                    node.core.disconnected(a.link, "connect failed", self.now)

    def _find(self, node: SimNode, link: int) -> tuple[int | None, int]:
        for cid, c in self.conns.items():
            for k in (0, 1):
                if c.ends[k] == (node, link) and c.open[k]:
                    return cid, k
        return None, 0

    def _connect(self, end: tuple[Any, int], addr: tuple, from_ip: str) -> int:
        """A connection from ``end`` to ``addr``: -1 when nothing listens there (or the
        way is cut); the other end accepts it after the delay."""
        to = self.nodes.get(addr[0])
        if to is None or not to.listening or addr[1] != PORT or self.udp.heals(from_ip, addr[0], self.now):
            return -1
        self._order += 1
        cid = self._order
        self.conns[cid] = _Conn([end, (to, 0)])
        self._stream(cid, 0, "syn", from_ip.encode())
        return cid

    def _stream(self, cid: int, end: int, kind: str, data: bytes) -> None:
        """Send ``data`` from ``end`` of connection ``cid`` to the other end: ordered,
        delayed; across a cut, it arrives after the cut heals."""
        c = self.conns[cid]
        if not c.open[end]:
            return
        if kind == "fin":
            c.open[end] = False
        src, dst = c.ends[end][0], c.ends[1 - end][0]
        at = self.now + self.udp.delay + (self.rng.random() * self.udp.jitter if self.udp.jitter else 0.0)
        a, b = getattr(src, "ip", "raw"), getattr(dst, "ip", "raw")
        heal = self.udp.heals(a, b, self.now)
        at = max(at, c.last[end], heal + self.udp.delay if heal is not None else 0.0)
        c.last[end] = at
        self._order += 1
        heapq.heappush(self._heap, (at, self._order, cid, 1 - end, kind, data))

    def _deliver(self) -> None:
        for src, dst, (addr, data) in self.udp.deliver():
            node = self.nodes.get(dst)
            if node is not None and not node.dead:
                self._deliver_to(node, ("udp", addr, data))
        while self._heap and self._heap[0][0] <= self.now:
            _, _, cid, end, kind, data = heapq.heappop(self._heap)
            who, _ = self.conns[cid].ends[end]
            if isinstance(who, RawConn):
                who.received += data
                who.closed = who.closed or kind == "fin"
            elif who is not None and not who.dead:
                self._deliver_to(who, ("tcp", cid, end, kind, data))

    def _deliver_to(self, node: SimNode, item: tuple) -> None:
        if node.paused:
            node.inbox.append(item)
            return
        core, now = node.core, self.now
        if item[0] == "udp":
            core.datagram(item[1], item[2], now)
            return
        _, cid, end, kind, data = item
        c = self.conns[cid]
        if kind == "syn":
            link = core.accepted((data.decode(), 40000 + cid % 20000), now) if node.listening else None
            if link is None:
                self._stream(cid, 1, "fin", b"")
                return
            c.ends[1] = (node, link)
        elif kind == "fin":
            c.open[end] = False
            core.received(c.ends[end][1], b"", now)
        else:
            core.received(c.ends[end][1], data, now)
        self._perform(node)


def circle_state(node: SimNode, n: int, t: float) -> P.State:
    """Tank ``n`` driving a circle of 5 m around (10 n, 20) at 2.5 m/s."""
    a = 0.5 * t + n
    x, z = 10.0 * n + 5.0 * math.cos(a), 20.0 + 5.0 * math.sin(a)
    return P.State(n, t, x, z, a + math.pi / 2, -2.5 * math.sin(a), 2.5 * math.cos(a), 0.5, 100.0, True)
