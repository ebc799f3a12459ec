"""Attacks on a session, in one process on loopback (issues 18 and 21): silent connections
that would lock a player out, forged datagrams with far-future sequence numbers, floods
of joins, wrong-password floods, and the rates of a host that runs many tanks."""

from __future__ import annotations

import socket
import threading
import time
from collections import Counter

import pytest
from net_helpers import guess_flood
from net_helpers import LOOPBACK, join, peers, play, pump, states_from  # noqa: F401 (peers: the fixture)
from net_helpers import session as _session

from tanktool.errors import NetError
from tanktool.net import auth, limits, probe
from tanktool.net import peer as peer_mod
from tanktool.net import protocol as P
from tanktool.net.peer import Peer

RATE = f"REFUSE {P.RefuseCode.RATE.value}"
PASSWORD = f"REFUSE {P.RefuseCode.PASSWORD.value}"


def _silent(address, n: int, peers, source: str | None = None) -> list[socket.socket]:
    """``n`` connections that never say anything (from ``source``), opened while the
    peers poll."""
    socks = []
    for _ in range(n):
        socks.append(probe.silent_connection(address, source))
        for p in peers:
            p.poll(0)
    return socks


# ---------------------------------------------------------------- pending connections
@pytest.mark.parametrize("password", [None, "pw"])
def test_silent_connections_do_not_lock_a_player_out(peers, password):
    _session(peers, 2, password)
    host = peers[0]
    socks = _silent(host.tcp_address, 300, peers)
    try:
        pump(peers, 0.3)
        # bounded, however many were opened
        assert len(host.pending) <= peer_mod.MAX_PENDING_PER_IP
        # (on a slow machine the first ones may have met their deadline before being pushed out)
        assert host.dropped["evicted"] + host.dropped["pending_timeout"] >= 300 - peer_mod.MAX_PENDING_PER_IP
        # while they are all still open, a real player joins, and links to player 2
        late = join(peers, host.tcp_address, "late", password, timeout=5.0)
        assert late.number == 3 and sorted(late.links) == [1, 2]
        pump(peers, 0.2)
        assert all(sorted(p.table) == [1, 2, 3] for p in peers)
        assert 3 in peers[1].links
    finally:
        for s in socks:
            s.close()


def test_a_flood_of_silent_connections_while_a_player_joins(peers):
    """An attacker opening connections without end (here ~1000 a second) while a real
    player joins: the player answers within a round trip, the flood never does."""
    _session(peers, 2)
    host = peers[0]
    stop = threading.Event()
    th = threading.Thread(target=probe.silent_flood, args=(host.tcp_address, stop, 400, 1000.0), daemon=True)
    th.start()
    try:
        pump(peers, 0.3)
        for name in ("late1", "late2"):
            join(peers, host.tcp_address, name, timeout=5.0)
        assert [p.number for p in peers] == [1, 2, 3, 4]
        assert len(host.pending) <= peer_mod.MAX_PENDING_PER_IP
    finally:
        stop.set()
        th.join(5)
    pump(peers, 0.2)
    assert all(sorted(p.table) == [1, 2, 3, 4] for p in peers)
    assert host.dropped["evicted"] > 0


def test_silent_connections_time_out_after_the_handshake_deadline(peers, monkeypatch):
    monkeypatch.setattr(limits, "PENDING_TIMEOUT", 1.0)
    _session(peers, 2)
    host = peers[0]
    socks = _silent(host.tcp_address, 5, peers)
    try:
        pump(peers, 0.1)
        assert len(host.pending) == 5
        pump(peers, 1.5)
        assert not host.pending and host.dropped["pending_timeout"] == 5
    finally:
        for s in socks:
            s.close()


def test_busiest_address_is_evicted_first(peers, monkeypatch):
    """Over the overall cap, the new connection pushes out one of the busiest address's,
    not one of a quieter address (a real player elsewhere)."""
    monkeypatch.setattr(limits, "MAX_PENDING", 6)
    host = Peer.host(("0.0.0.0", 0), "host")
    peers.append(host)
    port = host.tcp_address[1]
    quiet = _silent((LOOPBACK, port), 1, peers, source="127.0.0.2")      # another loopback address
    pump(peers, 0.1)
    loud = _silent((LOOPBACK, port), 20, peers)
    try:
        pump(peers, 0.2)
        ips = Counter(link.addr[0] for link in host.pending)
        assert ips["127.0.0.2"] == 1 and ips[LOOPBACK] == 5
    finally:
        for s in quiet + loud:
            s.close()


# ---------------------------------------------------------------- forged datagrams
def _forge_far_future(victim: Peer, target: Peer, seal_with: bytes | None = None) -> None:
    """One datagram from the victim's own address (as a spoofer would send it) claiming
    its tank, with a far-future sequence number."""
    data = P.encode(P.State(victim.number, victim.session_time(), 40.0, 40.0, 0, 0, 0, 0, 100, True),
                    victim.number, 10**9, time.time())
    if seal_with is not None:
        data = auth.seal(seal_with, data)
    elif target.password:
        data += bytes(auth.TAG_SIZE)        # a tag made without the key
    victim.udp.sendto(data, target.udp_address)


@pytest.mark.parametrize("password", [None, "s3cret"])
def test_forged_far_future_datagram_does_not_freeze_a_tank(peers, password):
    _session(peers, 3, password)
    host, b, c = peers
    before = play(peers, 0.5)
    assert states_from(before, 1, 2) >= 10
    _forge_far_future(b, host)
    after = play(peers, 1.0)
    # the real states of player 2 still flow to the host, and were never "stale"
    assert states_from(after, 1, 2) >= 20
    assert not [e for who, e in after if who == 1 and e.kind == "state" and e.body.x == 40.0]
    assert host.dropped["stale"] == 0 and host.dropped["rate"] == 0
    assert host.dropped["bad_mac" if password else "window"] == 1


def test_window_holds_even_with_the_right_key(peers):
    """Defence in depth: a far-future number is refused even on a datagram whose tag is
    right (here made with the pair's real key, which an outsider cannot derive)."""
    _session(peers, 2, "s3cret")
    host, b = peers
    play(peers, 0.3)
    key = host.links[2].udp_key
    assert key is not None and key == b.links[1].udp_key          # both ends derived the same key
    _forge_far_future(b, host, seal_with=key)
    after = play(peers, 0.6)
    assert host.dropped["window"] == 1 and host.dropped["stale"] == 0
    assert states_from(after, 1, 2) >= 10


def test_every_pair_has_its_own_key_and_unsealed_datagrams_are_refused(peers):
    _session(peers, 3, "pw")
    host, b, c = peers
    keys = {host.links[2].udp_key, host.links[3].udp_key, b.links[3].udp_key}
    assert len(keys) == 3 and None not in keys
    assert c.links[2].udp_key == b.links[3].udp_key
    play(peers, 0.3)
    # a datagram in the clear from a member's own address, and one sealed with another pair's key
    clear = P.encode(P.State(2, b.session_time(), 1, 1, 0, 0, 0, 0, 100, True), 2, b.seq + 5, time.time())
    b.udp.sendto(clear, host.udp_address)
    b.udp.sendto(auth.seal(c.links[2].udp_key, clear), host.udp_address)
    after = play(peers, 0.5)
    assert host.dropped["bad_mac"] == 2
    assert states_from(after, 1, 2) >= 8 and states_from(after, 1, 3) >= 8
    # a wrong password never gets a key: its HELLO or JOIN is refused
    with pytest.raises(NetError, match="wrong password"):
        join(peers, host.tcp_address, "guess", "PW")


def test_states_only_once_the_link_is_up(peers):
    """Without a link (no key, no sequence anchor) a datagram is refused, counted."""
    _session(peers, 2)
    host, b = peers
    host.window.forget(2)
    data = P.encode(P.State(2, 1.0, 1, 1, 0, 0, 0, 0, 100, True), 2, b.seq + 1, time.time())
    b.udp.sendto(data, host.udp_address)
    pump(peers, 0.1)
    assert host.dropped["no_anchor"] == 1


# ---------------------------------------------------------------- floods of joins
@pytest.mark.parametrize("password", [None, "pw"])
def test_join_flood_is_limited_and_real_peers_drop_nothing(peers, password):
    _session(peers, 3, password)
    host, b, c = peers
    replies: Counter = Counter()
    stop = threading.Event()

    def flood() -> None:
        end = time.monotonic() + 1.5
        while time.monotonic() < end and not stop.is_set():
            try:
                replies[probe.join_once(host.tcp_address, password)] += 1
            except OSError:
                replies["error"] += 1

    th = threading.Thread(target=flood, daemon=True)
    th.start()
    events = []
    while th.is_alive():
        events += play(peers, 0.1)
    stop.set()
    th.join(5)
    events += play(peers, 0.5)
    admitted = replies["NUMBER"]
    # at most the burst (refilled since the two real joins) and one a second after it
    assert admitted <= peer_mod.JOIN_BURST + 2, replies
    assert replies[RATE] >= 10, replies
    assert host.dropped["refused_rate"] == replies[RATE]
    # the real peers dropped none of the host's messages (nor anyone's) to their limiters
    for p in (b, c):
        assert p.dropped["rate"] == 0, dict(p.dropped)
        assert sorted(p.table) == [1, 2, 3]
    assert states_from(events, 2, 1) >= 30 and states_from(events, 3, 2) >= 30
    # and a real player from the same address gets in once the flood stops (it waits
    # for the limit when the host says "too many joins")
    late = join(peers, host.tcp_address, "late", password, timeout=5.0)
    pump(peers, 0.1)
    # (the flood's joiners used numbers: a number is not given twice while others are free)
    assert sorted(host.table) == sorted([1, 2, 3, late.number]) and late.number in b.table


def test_wrong_password_flood_is_cut_off(peers):
    _session(peers, 2, "pw")
    host = peers[0]
    replies = guess_flood(peers, host.tcp_address)
    # ten wrong answers are checked; after that the address's answers are not even looked at
    assert replies[PASSWORD] == peer_mod.AUTH_FAIL_BURST, replies
    assert replies[RATE] >= 15, replies
    assert host.dropped["refused_password"] == peer_mod.AUTH_FAIL_BURST


def test_join_limiter_per_address_and_overall():
    from tanktool.net.guard import JoinLimiter

    lim = JoinLimiter((1.0, 3.0), (2.0, 4.0), now=0.0)
    assert [lim.allow("a", 0.0) for _ in range(4)] == [True, True, True, False]     # a's burst
    assert lim.allow("b", 0.0) is True            # another address: the overall budget
    assert lim.allow("c", 0.0) is False           # the overall burst (4) is spent
    assert lim.allow("a", 1.0) is True            # a second later: one more each
    assert lim.allow("c", 1.0) is True


def test_a_host_with_seven_bots_is_not_rate_limited(peers):
    """The UDP limit is per tank: a host sending the states of 7 computer opponents
    besides its own (240 a second) is not cut by the member's limiter."""
    _session(peers, 2)
    host, b = peers
    bots = [host.add_bot(f"bot{k}") for k in range(6)]
    assert bots == [3, 4, 5, 6, 7, 8]
    pump(peers, 0.1)
    end = time.monotonic() + 1.5
    got = Counter()
    next_t = time.monotonic()
    while time.monotonic() < end:
        if time.monotonic() >= next_t:
            next_t += 1 / 30
            for n in [1] + bots:
                host.send_state(P.State(n, host.session_time(), 5.0, 5.0, 0, 0, 0, 0, 100, True))
        host.poll(0.002)
        for e in b.poll(0.002):
            if e.kind == "state":
                got[e.body.tank] += 1
    assert b.dropped["rate"] == 0
    assert all(got[n] >= 35 for n in [1] + bots), got
