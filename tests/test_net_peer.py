"""Sessions in one process on loopback: joins, the mesh, refusals, host migration,
impostors, garbage and passwords."""

from __future__ import annotations

import socket

import pytest
from net_helpers import LOOPBACK, join, peers, pump  # noqa: F401 (peers: the fixture)
from net_helpers import session as _session

from tanktool.errors import NetError
from tanktool.net import protocol as P
from tanktool.net.peer import Peer, parse_address


def test_full_mesh_and_same_table(peers):
    _session(peers, 4)
    assert [p.number for p in peers] == [1, 2, 3, 4]
    for p in peers:
        assert sorted(p.table) == [1, 2, 3, 4]
        assert sorted(p.links) == sorted({1, 2, 3, 4} - {p.number})     # full mesh
        assert p.host_number == 1
        assert {n: e.name for n, e in p.table.items()} == {1: "host", 2: "peer2", 3: "peer3", 4: "peer4"}
    # the session clock is shared: every joiner is within a few ms of the host
    times = [p.session_time() for p in peers]
    assert max(times) - min(times) < 0.05


def test_states_events_and_latest_sequence_wins(peers):
    _session(peers, 3)
    events = pump(peers, 0.3, states=True)
    got = {(me, e.number) for me, e in events if e.kind == "state"}
    assert got == {(a, b) for a in (1, 2, 3) for b in (1, 2, 3) if a != b}
    # a shot by TCP reaches everyone else
    peers[1].send_event(P.Shot(2, 1.0, 3.0, 4.0, 0.5, 0.0, 0.0))
    events = pump(peers, 0.2)
    shots = {me for me, e in events if e.kind == "shot" and e.body.tank == 2}
    assert shots == {1, 3}
    # a replayed (older) datagram is dropped as stale
    s = P.State(2, 1.0, 0, 0, 0, 0, 0, 0, 100, True)
    old = P.encode(s, 2, 1, 1.0)
    sock = peers[1].udp
    sock.sendto(old, peers[0].udp_address)
    before = peers[0].dropped["stale"]
    pump(peers, 0.1)
    assert peers[0].dropped["stale"] == before + 1


def test_ninth_refused(peers):
    _session(peers, 8)
    assert sorted(peers[0].table) == list(range(1, 9))
    with pytest.raises(NetError, match="session full"):
        join(peers, peers[0].tcp_address, "ninth")
    assert len(peers) == 8 and all(len(p.table) == 8 for p in peers)


def test_a_newcomer_gets_a_number_never_used_and_the_host_stays(peers):
    _session(peers, 4)
    peers[1].close()                           # player 2 leaves cleanly (EXIT)
    pump(peers, 0.2)
    assert all(sorted(p.table) == [1, 3, 4] for p in peers if not p.closed)
    newcomer = join(peers, peers[0].tcp_address, "again")
    assert newcomer.number == 5 and newcomer.host_number == 1
    pump(peers, 0.1)
    assert all(sorted(p.table) == [1, 3, 4, 5] for p in peers if not p.closed)


def test_host_crash_migrates_and_new_host_takes_joins(peers):
    _session(peers, 4)
    peers[0].close(send_exit=False)            # the host vanishes (its links close)
    events = pump(peers, 0.3)
    alive = [p for p in peers if not p.closed]
    assert all(p.host_number == 2 for p in alive)
    assert peers[1].is_host and not peers[2].is_host
    assert all(p.host_changes and p.host_changes[-1][1] == 2 for p in alive)
    assert {me for me, e in events if e.kind == "host" and e.number == 2} == {2, 3, 4}
    # a new player joins through the new host and gets a number never used
    newcomer = join(peers, peers[1].tcp_address, "late")
    assert newcomer.number == 5 and newcomer.host_number == 2
    pump(peers, 0.1)
    for p in peers:
        if not p.closed:
            assert sorted(p.table) == [2, 3, 4, 5] and p.host_number == 2
            assert sorted(p.links) == sorted({2, 3, 4, 5} - {p.number})
    # joining through a member that is not the host is redirected to the host
    peers[2].close()
    pump(peers, 0.1)
    other = join(peers, peers[3].tcp_address, "redirected")
    assert other.number == 6 and other.host_number == 2


def test_silent_host_is_replaced(peers):
    host = Peer.host((LOOPBACK, 0), "host", silence=0.5)
    peers.append(host)
    for i in (2, 3):
        join(peers, host.tcp_address, f"p{i}", silence=0.5)
    # the host stops polling and sending (a frozen process); 2 and 3 keep talking
    pump(peers[1:], 1.0, states=True)
    assert all(p.host_number == 2 for p in peers[1:])
    assert 1 not in peers[1].table and 1 not in peers[2].table


def test_impostor_state_and_events_ignored(peers):
    _session(peers, 3)
    pump(peers, 0.1, states=True)
    rogue = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        fake = P.encode(P.State(2, 5.0, 999.0, 999.0, 0, 0, 0, 0, 100, True), 2, 10**6, 1.0)
        for p in peers:
            rogue.sendto(fake, p.udp_address)
        # player 3's own socket claiming to be player 2
        peers[2].udp.sendto(fake, peers[0].udp_address)
    finally:
        rogue.close()
    # player 3 claims, over its own TCP link, a hit on player 2 and a shot of player 1
    peers[2].send_event(P.Hit(3, 2, 1.0, 25.0, 0.0, True, 0, 0))
    peers[2].send_event(P.Shot(1, 1.0, 0, 0, 0, 0, 0))
    events = pump(peers, 0.2)
    assert not [e for _, e in events if e.kind == "state" and e.body.x == 999.0]
    assert not [e for _, e in events if e.kind in ("hit", "shot")]
    # (player 3's datagram: an impostor, or dropped unread when the pump above used up
    # its address's budget; its HIT: only the host decides hits)
    host = peers[0].dropped
    assert host["impostor"] + host["flood"] >= 2 and host["not_host"] >= 1 and peers[1].dropped["impostor"] >= 1
    # a forged HELLO for a number that is already linked is refused
    s = socket.create_connection(peers[0].tcp_address, timeout=2)
    try:
        s.sendall(P.encode(P.Hello(peers[0].table[2].epoch, bytes(32)), 2, 1, 1.0))
        pump(peers, 0.2)
        data = s.recv(4096)
        assert P.MessageType.REFUSE in [m.type for m in P.StreamReader(peers[0].dropped).feed(data)]
    finally:
        s.close()
    assert all(sorted(p.table) == [1, 2, 3] for p in peers)


def test_garbage_to_every_port_changes_nothing(peers):
    _session(peers, 3)
    pump(peers, 0.1, states=True)
    tables = [dict(p.table) for p in peers]
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    good = P.encode(P.State(1, 1.0, 0, 0, 0, 0, 0, 0, 100, True), 1, 5, 1.0)
    try:
        for p in peers:
            for k in range(len(good)):
                udp.sendto(good[:k], p.udp_address)                 # truncations
            udp.sendto(b"\xff" * 600, p.udp_address)
            udp.sendto(good + b"x", p.udp_address)
            for junk in (b"GET / HTTP/1.0\r\n\r\n", good[:30], b"\x00" * 5000):
                t = socket.create_connection(p.tcp_address, timeout=2)
                t.sendall(junk)
                t.close()
    finally:
        udp.close()
    pump(peers, 0.5, states=True)
    for p, before in zip(peers, tables):
        assert p.table == before and p.host_number == 1
        assert sorted(p.links) == sorted({1, 2, 3} - {p.number})
        assert sum(p.dropped.values()) >= len(good) + 2
        assert not p.pending           # every junk connection was closed


def test_password(peers):
    host = Peer.host((LOOPBACK, 0), "host", "s3cret")
    peers.append(host)
    with pytest.raises(NetError, match="wants a password"):
        join(peers, host.tcp_address, "nopw")
    with pytest.raises(NetError, match="wrong password"):
        join(peers, host.tcp_address, "badpw", "guess")
    ok = join(peers, host.tcp_address, "good", "s3cret")
    third = join(peers, host.tcp_address, "good2", "s3cret")
    assert ok.number == 2 and third.number == 3 and 2 in third.links   # HELLO passed the HMAC too
    assert host.dropped["refused_password"] == 1


def test_bad_addresses_and_port_in_use(peers):
    for text in ("nonsense", "1.2.3:80", "127.0.0.1:99999", "127.0.0.1:x"):
        with pytest.raises(NetError):
            parse_address(text, need_host=True)
    assert parse_address("5000") == ("127.0.0.1", 5000)
    assert parse_address("0.0.0.0:7") == ("0.0.0.0", 7)
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    with pytest.raises(NetError, match="in use"):
        Peer.host(host.tcp_address, "again")
    free = socket.socket()
    free.bind((LOOPBACK, 0))
    port = free.getsockname()[1]
    free.close()
    with pytest.raises(NetError, match="cannot reach"):
        Peer.join((LOOPBACK, port), "nobody", timeout=1.0)


def test_exit_seen_only_by_the_host_reaches_everyone(peers):
    _session(peers, 3)
    # a player that joins and leaves before it ever polls: its mesh links never got
    # past the challenge, so its EXIT reaches only the host; the host's TABLE takes it
    # out of every table
    ghost = join(peers, peers[0].tcp_address, "ghost", settle=False, link_wait=0)     # the ghost never polls
    pump(peers, 0.1)
    assert ghost.number == 4 and all(4 in p.table for p in peers)
    assert all(4 not in p.links for p in peers[1:])           # only pending links at 2 and 3
    ghost.close()
    events = pump(peers, 0.3)
    assert all(sorted(p.table) == [1, 2, 3] for p in peers)
    assert {me for me, e in events if e.kind == "left" and e.reason == "dropped by the host"} == {2, 3}
    # and when the host then dies, everyone agrees on 2 (not on the ghost)
    peers[0].close(send_exit=False)
    pump(peers, 0.2)
    assert peers[1].host_number == 2 and peers[2].host_number == 2


def test_simultaneous_links_keep_one(peers):
    _session(peers, 3)
    a, b = peers[1], peers[2]
    # a second link between 2 and 3, opened by 2 as if both had dialled at once
    a._close_link(a.links[3])
    b._close_link(b.links[2])
    pump(peers, 0.1)          # the closes look like exits; bring both back through the host's table
    for p in peers:
        p.table.update({2: a.table.get(2) or peers[0].table[2], 3: b.table.get(3) or peers[0].table[3]})
    a._link_to(a.table[3])
    b._link_to(b.table[2])
    pump(peers, 0.3)
    assert 3 in a.links and 2 in b.links
    assert a.links[3].initiated != b.links[2].initiated     # one link, opened by one side
    assert sorted(a.table) == [1, 2, 3] and sorted(b.table) == [1, 2, 3]


def test_bots_belong_to_the_host_and_move_on_migration(peers):
    _session(peers, 3)
    host = peers[0]
    bots = [host.add_bot("bot1"), host.add_bot("bot2")]
    assert bots == [4, 5]
    pump(peers, 0.2)
    for p in peers:
        assert p.table[4].owner == 1 and p.table[5].is_bot
        assert sorted(p.links) == sorted({1, 2, 3} - {p.number})       # nobody links to a bot
    assert host.speaks_for() == [1, 4, 5] and peers[1].speaks_for() == [2]
    # the host's states for its bots are taken; player 3 speaking for bot 4 is not
    host.send_state(P.State(4, 1.0, 7.0, 7.0, 0, 0, 0, 0, 100, True))
    peers[2].send_state(P.State(4, 1.1, 999.0, 999.0, 0, 0, 0, 0, 100, True))
    events = pump(peers, 0.2)
    seen = {(me, e.body.x) for me, e in events if e.kind == "state" and e.body.tank == 4}
    assert seen == {(2, 7.0), (3, 7.0)}
    # a hit on a bot is decided by its owner only
    peers[2].send_event(P.Hit(3, 4, 1.0, 25.0, 0.0, True, 0, 0))
    host.send_event(P.Hit(2, 4, 1.0, 25.0, 75.0, False, 0, 0))
    hits = {(me, e.body.shooter) for me, e in pump(peers, 0.2) if e.kind == "hit"}
    assert hits == {(2, 2), (3, 2)}
    # the host crashes: player 2 hosts and adopts the bots, everyone agrees
    host.close(send_exit=False)
    events = pump(peers, 0.3)
    for p in peers[1:]:
        assert p.host_number == 2 and p.table[4].owner == 2 and p.table[5].owner == 2
    assert {e.number for me, e in events if e.kind == "adopt"} == {4, 5}
    assert all(me == 2 for me, e in events if e.kind == "adopt")
    assert peers[1].speaks_for() == [2, 4, 5]
    # room is counted with the bots: 2 players + 2 bots + 4 more bots fill the 8 places
    for i in range(4):
        assert peers[1].add_bot(f"more{i}") is not None
    assert peers[1].add_bot("too many") is None
    with pytest.raises(NetError, match="session full"):
        join(peers, peers[1].tcp_address, "late")
