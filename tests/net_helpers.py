"""Helpers for the network tests: in-process peers pumped together, loopback only."""

from __future__ import annotations

import threading
import time
from collections import Counter

import pytest

from tanktool.net import probe
from tanktool.net import protocol as P
from tanktool.net.peer import Peer

LOOPBACK = "127.0.0.1"


def pump(peers, seconds: float = 0.2, states: bool = False) -> list:
    """Poll every open peer for ``seconds`` (bounded); optionally send states, 60 a
    second each (twice the game's rate: more would be a member's flood, which the
    peers drop unread, and would run the senders' numbers past the sequence window)."""
    events = []
    end = time.monotonic() + seconds
    next_state = time.monotonic()
    while time.monotonic() < end:
        send = states and time.monotonic() >= next_state
        if send:
            next_state += 1.0 / 60.0
        for p in peers:
            if p.closed:
                continue
            if send and p.number:
                p.send_state(P.State(p.number, max(p.session_time(), 0.0), 1.0 * p.number, 2.0, 0.0,
                                     0.0, 0.0, 0.0, 100.0, True))
            events += [(p.number, e) for e in p.poll(0.002)]
    return events


def join(peers, address, name: str, password: str | None = None, timeout: float = 5.0, settle: bool = True,
         **kw) -> Peer:
    """Peer.join blocks on its handshake, so run it in a thread while the others poll;
    then (``settle``) add it to ``peers`` and let the mesh form."""
    out: dict = {}

    def run() -> None:
        try:
            out["peer"] = Peer.join(address, name, password, timeout=timeout, **kw)
        except Exception as e:          # handed to the test thread
            out["error"] = e

    th = threading.Thread(target=run, daemon=True)
    th.start()
    deadline = time.monotonic() + timeout + 5.0
    while th.is_alive() and time.monotonic() < deadline:
        for p in peers:
            if not p.closed:
                p.poll(0.002)
    th.join(1.0)
    if "error" in out:
        raise out["error"]
    peer = out["peer"]
    if settle:
        peers.append(peer)
        pump(peers, 0.1)
    return peer


def close_all(peers) -> None:
    for p in peers:
        p.close(send_exit=False)


def play(peers, seconds: float, hz: float = 30.0) -> list:
    """Poll every open peer for ``seconds``, each sending its own tank's state ``hz``
    times a second (the real rate, unlike ``pump(states=True)`` which floods)."""
    events = []
    end = time.monotonic() + seconds
    next_state = time.monotonic()
    while time.monotonic() < end:
        if time.monotonic() >= next_state:
            next_state += 1.0 / hz
            for p in peers:
                if not p.closed and p.number:
                    p.send_state(P.State(p.number, max(p.session_time(), 0.0), 1.0 * p.number, 2.0, 0.0,
                                         0.0, 0.0, 0.0, 100.0, True))
        for p in peers:
            if not p.closed:
                events += [(p.number, e) for e in p.poll(0.002)]
    return events


def states_from(events, me: int, sender: int) -> int:
    """How many states from ``sender`` player ``me`` took."""
    return sum(1 for who, e in events if who == me and e.kind == "state" and e.number == sender)


@pytest.fixture
def peers():
    """In-process peers made by a test, all closed at its end (import it into the test
    module: ``from net_helpers import peers``)."""
    made: list[Peer] = []
    yield made
    close_all(made)


def session(peers, n: int, password: str | None = None, **kw) -> list[Peer]:
    """A host and ``n - 1`` joiners, in ``peers``, the mesh formed (``kw``: Peer's,
    e.g. ``silence``)."""
    host = Peer.host((LOOPBACK, 0), "host", password, **kw)
    peers.append(host)
    for i in range(2, n + 1):
        join(peers, host.tcp_address, f"peer{i}", password, **kw)
    return peers


def match_kw(arena: str = "box", vehicle: str | None = None) -> dict:
    """The ``digest`` and ``label`` a peer playing ``arena`` with ``vehicle`` joins with,
    as ``tanktool play`` and the window compute them (a host refuses other digests)."""
    from tanktool.net.digest import match_digest, match_label
    from tanktool.sim.match import choose_vehicle, load_match_arena, load_tank_spec

    info = load_match_arena(arena)
    spec = load_tank_spec(choose_vehicle(info, vehicle, lambda line: None))
    return {"digest": match_digest(info, spec), "label": match_label(info, spec)}


def guess_flood(peers, address, guesses: int = 30) -> Counter:
    """``guesses`` joins with a wrong password from one address, made in a thread while
    ``peers`` poll; the host's replies counted (``probe.join_once``'s words)."""
    replies: Counter = Counter()
    th = threading.Thread(target=lambda: replies.update(probe.join_once(address, "guess") for _ in range(guesses)),
                          daemon=True)
    th.start()
    while th.is_alive():
        pump(peers, 0.05)
    th.join()
    return replies
