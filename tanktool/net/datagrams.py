"""Datagrams: sending states, reading them (the per-address budget, the tag, the
sender's address, the sequence window, the per-tank rate).  No I/O: part of
:class:`~tanktool.net.core.Core`."""

from __future__ import annotations

from . import protocol as P
from .auth import TAG_SIZE, seal, unseal
from . import limits as L
from .guard import Bucket
from .links import NetEvent, SendTo


class DatagramsMixin:
    """States over UDP."""

    def send_state(self, state: P.State, now: float) -> None:
        """A state of a tank I run to every other player, by UDP (with a password, each
        copy sealed with the key of that player's link; none goes to a player whose
        link is not up yet)."""
        self.now = now
        if self.closed:
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
            self.counters["sent"] += 1
            self.counters["states_sent"] += 1
            self.counters["bytes_sent"] += len(out)
            self.actions.append(SendTo((e.ip, e.udp_port), out))

    def unsent(self, data: bytes) -> None:
        """The transport could not send a datagram the core counted as sent."""
        self.dropped["send_failed"] += 1
        self.counters["sent"] -= 1
        self.counters["states_sent"] -= 1
        self.counters["bytes_sent"] -= len(data)

    def datagram(self, addr: tuple, data: bytes, now: float) -> None:
        """A datagram arrived from ``addr`` (ip, port)."""
        self.now = now
        self.counters["bytes_received"] += len(data)
        self.dropped.source = addr
        if not self._udp_budget(addr, now):
            # a member over what its tanks may send: dropped before any tag or decode,
            # so its flood costs a dictionary look-up, not the others' states (finding 8)
            self.dropped["flood"] += 1
            return
        if self.password:
            data = self._unseal(data, addr)
            if data is None:
                return
        m = P.decode(data, self.dropped)
        if m is None:
            return
        if self._from_member(m.sender, addr) is None:
            return
        if not isinstance(m.body, P.State):
            self.dropped["unexpected"] += 1
            return
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
            b = self.addr_buckets[addr] = Bucket(L.UDP_RATE * tanks, L.UDP_BURST * tanks, now)
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
        body, reason = m.body, ""
        if self.judge is not None:
            # what its vehicle could have done (judge.py): a state beyond it shows the
            # last valid pose; None: older than what the judge holds
            was_alive = self.judge.alive(body.tank)
            body = self.judge.state(body, self.session_time())
            if body is None:
                return True
            if body.alive and not was_alive:
                reason = "respawn"
        self.events.append(NetEvent("state", m.sender, body, reason))
        return True
