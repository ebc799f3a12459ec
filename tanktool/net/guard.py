"""What keeps a session up under attack: rate limits, the join limiter, the sequence
window of states, and the drop log that says at ``-v`` what was turned away.

Each piece is a small policy with the clock passed in, so tests can drive it
directly and :class:`~tanktool.net.peer.Peer` only asks it questions.
"""

from __future__ import annotations

from collections import Counter
from typing import Any, Hashable


class Bucket:
    """Token bucket: ``rate`` messages a second with bursts up to ``burst``."""

    __slots__ = ("rate", "burst", "tokens", "last")

    def __init__(self, rate: float, burst: float, now: float) -> None:
        self.rate, self.burst, self.tokens, self.last = rate, burst, burst, now

    def take(self, now: float) -> bool:
        self.tokens = min(self.burst, self.tokens + (now - self.last) * self.rate)
        self.last = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        return False

    def full(self, now: float) -> bool:
        return self.tokens + (now - self.last) * self.rate >= self.burst


class Buckets:
    """One bucket per key (an address, a sender), created full; buckets that have filled
    up again are forgotten by :meth:`prune`, so an attacker with many addresses costs
    memory only while it is sending, and at most ``max_keys`` buckets are kept."""

    def __init__(self, rate: float, burst: float, max_keys: int = 4096) -> None:
        self.rate, self.burst, self.max_keys = rate, burst, max_keys
        self.buckets: dict[Hashable, Bucket] = {}

    def take(self, key: Hashable, now: float) -> bool:
        b = self.buckets.get(key)
        if b is None:
            if len(self.buckets) >= self.max_keys:
                self.prune(now)
                if len(self.buckets) >= self.max_keys:
                    return False      # too many senders at once: the newest waits
            b = self.buckets[key] = Bucket(self.rate, self.burst, now)
        return b.take(now)

    def has_token(self, key: Hashable, now: float) -> bool:
        """Whether ``take`` would succeed now (without taking)."""
        b = self.buckets.get(key)
        return b is None or b.tokens + (now - b.last) * b.rate >= 1.0

    def prune(self, now: float) -> None:
        for key in [k for k, b in self.buckets.items() if b.full(now)]:
            del self.buckets[key]

    def forget(self, key: Hashable) -> None:
        self.buckets.pop(key, None)


class JoinLimiter:
    """Joins per address, and joins overall.

    Every admitted join makes the host send the new table to every member (and a
    leave, another), so joins are what an attacker would flood to fill the members'
    own rate limiters with the host's messages.  ``per_address`` caps one address
    (a burst that lets a LAN party or a whole loopback test session in at once, then
    a steady rate); ``overall`` caps what many addresses together can make the host
    send.  An address over its limit does not use the overall budget.
    """

    def __init__(self, per_address: tuple[float, float], overall: tuple[float, float], now: float) -> None:
        self.addresses = Buckets(*per_address)
        self.overall = Bucket(*overall, now)

    def allow(self, ip: str, now: float) -> bool:
        return self.addresses.take(ip, now) and self.overall.take(now)


class SeqWindow:
    """Which sequence numbers a sender's states may carry.

    A sender numbers every message it sends (TCP and UDP, one counter), so its numbers
    cannot run ahead of real time faster than it sends: at most ``rate`` a second (8
    tanks' states at 30 Hz and their events are under 300).  A state is admitted when

        seq <= anchor + slack + rate * (now - anchor time)

    where the anchor is the highest number seen from that sender on its TCP link (whose
    handshake authenticated it) or in an admitted state.  A forged datagram with a
    far-future number is refused instead of making every real state after it "stale";
    a sender without an anchor (no link yet) is refused too.  Older numbers are the
    caller's business (latest state wins).
    """

    def __init__(self, slack: int = 256, rate: float = 1000.0) -> None:
        self.slack, self.rate = slack, rate
        self.anchors: dict[int, tuple[int, float]] = {}

    def anchor(self, sender: int, seq: int, now: float) -> None:
        old = self.anchors.get(sender)
        if old is None or seq > old[0]:
            self.anchors[sender] = (seq, now)

    def admits(self, sender: int, seq: int, now: float) -> bool | None:
        """True within the window, False past it, None when ``sender`` has no anchor."""
        a = self.anchors.get(sender)
        if a is None:
            return None
        return seq <= a[0] + self.slack + self.rate * max(now - a[1], 0.0)

    def forget(self, sender: int) -> None:
        self.anchors.pop(sender, None)


#: what each drop reason means, for the log lines (reasons not listed print as they are)
KINDS = {
    "short": "malformed messages (too short)", "magic": "malformed messages (bad magic)",
    "version": "messages of another protocol version", "type": "malformed messages (unknown type)",
    "sender": "malformed messages (bad sender)", "length": "malformed messages (bad length)",
    "nan": "malformed messages (NaN or inf)", "range": "malformed messages (values out of range)",
    "name": "malformed messages (bad name)", "payload": "malformed messages (bad payload)",
    "overflow": "TCP streams over their buffer",
    "garbage_stream": "connections closed for sending garbage",
    "impostor": "messages speaking for another player or from another address",
    "unknown": "datagrams from senders not in the table",
    "not_host": "table messages from a player who is not the host",
    "unexpected": "messages of a type not expected there",
    "stale": "stale states (an older sequence number than one already seen)",
    "window": "states with a sequence number beyond the window (forged far-future?)",
    "no_anchor": "states from a player whose link is not up yet",
    "bad_mac": "datagrams with a missing or wrong MAC",
    "no_key": "datagrams from a player without a link key yet",
    "rate": "messages over the per-link / per-tank rate limit",
    "refused_rate": "joins refused: over the per-address join limit",
    "refused_password": "joins or links refused: wrong password",
    "refused_full": "joins refused: session full",
    "refused_not_host": "joins redirected: not the host",
    "refused_bad_request": "links refused: bad request",
    "evicted": "silent connections closed to make room for a new one",
    "too_many_pending": "connections refused: too many unidentified at once",
    "pending_timeout": "connections closed: said nothing within the handshake deadline",
    "link_failed": "mesh links that could not be opened",
    "send_failed": "datagrams the system would not send",
    "flood": "datagrams from a member over what its tanks may send (dropped unread)",
    "stepped_down": "probes that found a newer session (this peer stepped down)",
    "refused_mismatch": "joins refused: another arena or vehicle (digests differ)",
    "refused_name": "joins refused: a blank name or one like a player's",
}


class DropLog(Counter):
    """Drop reason -> count (the JSON report's ``dropped_reasons``), which also notes
    where each drop came from: set :attr:`source` to the address being read before
    handling its data.  :meth:`lines` gives one line per reason that grew since the
    last call, with its count and its main sources: at ``-v`` an attack leaves a
    trace in the log without a line per packet."""

    MAX_SOURCES = 64

    def __init__(self, *args: Any, **kw: Any) -> None:
        super().__init__(*args, **kw)
        self.source: Any = None
        self.sources: dict[str, Counter] = {}
        self._said: Counter = Counter()
        #: something was dropped since the last :meth:`lines`
        self.grown = False

    def __setitem__(self, key: str, value: int) -> None:
        grew = value - self.get(key, 0)
        super().__setitem__(key, value)
        if grew > 0:
            self.grown = True
            where = self.sources.get(key)
            if where is None:
                where = self.sources[key] = Counter()
            src = _where(self.source)
            if src in where or len(where) < self.MAX_SOURCES:
                where[src] += grew
            else:
                where["others"] += grew

    def lines(self, seconds: float | None = None) -> list[str]:
        """One line per reason with new drops since the last call (``seconds``: how long
        that was, said in the line)."""
        self.grown = False
        out = []
        for key in sorted(self):
            n = self[key] - self._said.get(key, 0)
            if n <= 0:
                continue
            self._said[key] = self[key]
            where = self.sources.pop(key, Counter())
            where.pop("-", None)                  # drops with no address to name
            top = ", ".join(f"{s} ({k})" for s, k in where.most_common(3))
            more = len(where) - 3
            span = f" in the last {seconds:.0f} s" if seconds is not None else ""
            out.append(f"network: {n} {key}{span}: {KINDS.get(key, key)}"
                       + (f"; from {top}" + (f" and {more} more" if more > 0 else "") if top else ""))
        return out


def _where(source: Any) -> str:
    if source is None:
        return "-"
    if isinstance(source, tuple):
        return f"{source[0]}:{source[1]}" if len(source) >= 2 else str(source[0])
    return str(source)
