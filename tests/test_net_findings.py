"""Issue 27's findings 1, 2, 3, 5 and 7, each reproduced (these failed before the fix),
the match digest of issue 25 (peers on different arenas refuse the match), and the
second Ctrl-C while the host shuts down."""

from __future__ import annotations

import os
import signal
import socket
import threading
import time
from collections import Counter

import pytest
from net_helpers import guess_flood
from net_helpers import LOOPBACK, join, match_kw, peers, play, pump, states_from  # noqa: F401 (peers: the fixture)
from net_helpers import session as _session

from tanktool.errors import NetError
from tanktool.net import probe
from tanktool.net import protocol as P
from tanktool.net.names import name_key, name_problem, visible
from tanktool.net.core import Core
from tanktool.net.links import Send
from tanktool.net.peer import Peer


# ---------------------------------------------------------------- finding 1
def test_a_newcomer_after_a_leaver_is_seen_by_every_member(peers):
    """B leaves, C joins: C used to get B's number *and* epoch, and A, which lists
    (B's number, epoch) as departed, never showed C."""
    _session(peers, 3)
    host, a, b = peers
    b_epoch = host.table[3].epoch
    b.close()
    pump(peers, 0.2)
    c = join(peers, host.tcp_address, "carol")
    pump(peers, 0.2)
    assert (c.number, c.table[c.number].epoch) != (3, b_epoch)
    assert c.table[c.number].epoch > max(e.epoch for e in host.table.values() if e.number != c.number)
    for p in (host, a):
        assert c.number in p.table and p.table[c.number].name == "carol"
    assert c.number in a.links
    events = play([host, a, c], 0.5)
    assert states_from(events, a.number, c.number) > 3


def test_numbers_and_epochs_are_not_reused_while_others_are_free(peers):
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    bots = [host.add_bot(f"b{k}") for k in range(7)]
    assert bots == [2, 3, 4, 5, 6, 7, 8] and [host.table[n].epoch for n in bots] == [2, 3, 4, 5, 6, 7, 8]
    host._remove(5, "test")
    host._remove(3, "test")
    # every number was used: the one freed longest ago, with an epoch never given
    n = host.add_bot("again")
    assert n == 5 and host.table[5].epoch == 9
    assert host.add_bot("more") == 3 and host.table[3].epoch == 10


# ---------------------------------------------------------------- finding 2
def test_admitting_while_sends_fail_does_not_crash_the_host():
    """The host admits a joiner while the link to an earlier member fails and the
    joiner itself has already gone: the cleanup used to remove the joiner before
    ``_admit`` read its entry (KeyError).  The core sends nothing itself: the transport
    reports the failed sends after the admission is done."""
    core = Core("host")
    core.start_host((LOOPBACK, 5000, 5000), now=0.0)
    core.table[2] = P.Entry(2, 2, LOOPBACK, 40001, 40001, "early")
    core._saw(core.table[2])
    early = core._new_link((LOOPBACK, 40001))
    core._bind_link(early, 2)
    joiner = core.accepted((LOOPBACK, 40000), now=0.1)
    assert joiner is not None and [type(a) for a in core.take_actions()] == [Send]      # the challenge
    join = P.encode(P.Join("newbie", 40002, 40002, bytes(P.MAC_SIZE), core.digest), 0, 1, 0.1)
    core.received(joiner, join, now=0.2)
    sends = [a for a in core.take_actions() if isinstance(a, Send)]
    assert {a.link for a in sends} == {joiner, early.id}       # NUMBER to it, NEW_PLAYER to 2
    for a in sends:                                            # both sends fail
        core.disconnected(a.link, "closed", now=0.3)
    kinds = [(e.kind, e.number) for e in core.take_events()]
    assert ("joined", 3) in kinds and ("left", 3) in kinds and ("left", 2) in kinds
    assert sorted(core.table) == [1] and not core.links and not core.pending and not core.conns


# ---------------------------------------------------------------- finding 3
def test_strangers_knocking_do_not_push_the_host_out_of_the_members_window(peers):
    """Every connection gets a challenge; they used to advance the host's message
    counter, so 300 strangers put its states past the members' window (slack 256)."""
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    frozen = time.time()
    member = join(peers, host.tcp_address, "member", clock=lambda: frozen)   # no window growth with time
    socks = []
    try:
        for _ in range(300):
            socks.append(probe.silent_connection(host.tcp_address))
            host.poll(0)
        pump([host], 0.3)
        assert host.dropped["evicted"] + len(host.pending) >= 290          # they were all challenged
        before = states_from([], 0, 0)
        events = play([host, member], 0.4)
        assert states_from(events, member.number, 1) > 3 + before
        assert member.dropped["window"] == 0
    finally:
        for s in socks:
            s.close()


# ---------------------------------------------------------------- finding 5
def _hello(peers, address, sender: int, epoch: int) -> socket.socket:
    """A connection that answers the challenge with a HELLO for ``sender``/``epoch``."""
    s = socket.create_connection(address, timeout=2)
    pump(peers, 0.01)
    s.recv(4096)                                               # the challenge
    s.sendall(P.encode(P.Hello(epoch, bytes(P.MAC_SIZE)), sender, 1, time.time()))
    return s


def test_parked_hellos_and_silent_connections_do_not_lock_joiners_out(peers):
    # nobody sends states here: on a loaded machine the floods below take longer than
    # the 3 s after which a quiet member counts as gone (the table then lacked peer2)
    _session(peers, 2, silence=60.0)
    host, member = peers
    parked = []
    stop = threading.Event()
    th = threading.Thread(target=probe.silent_flood, args=(host.tcp_address, stop, 40, 300.0), daemon=True)
    try:
        for k in range(48):
            parked.append(_hello(peers, host.tcp_address, 5, 99))           # a player the host never had
            parked.append(_hello(peers, member.tcp_address, 6, 50 + k))     # future epochs at a member
            pump(peers, 0.003)
        pump(peers, 0.2)
        assert sum(1 for link in host.pending if link.hello is not None) == 0
        assert sum(1 for link in member.pending if link.hello is not None) <= 5
        th.start()
        for k in range(5):
            join(peers, host.tcp_address, f"real{k}", timeout=3.0)
        pump(peers, 0.2)
        assert len(host.table) == 7
        for p in peers:
            assert sorted(p.links) == sorted(set(host.table) - {p.number})
    finally:
        stop.set()
        if th.is_alive():
            th.join(5)
        for s in parked:
            s.close()


def test_wrong_passwords_from_a_players_address_do_not_lock_it_out(peers):
    _session(peers, 2, "pw")
    host = peers[0]
    replies = guess_flood(peers, host.tcp_address)
    assert replies[f"REFUSE {P.RefuseCode.RATE.value}"] >= 15, replies
    # right away, from the same address, the real player proves the password and gets in
    real = join(peers, host.tcp_address, "real", "pw", timeout=0.3)
    assert real.number in host.table


# ---------------------------------------------------------------- finding 7
@pytest.mark.parametrize("name", ["hоst", "HOST", "ｈｏｓｔ", "ho\u0455t", "bob", "b\u043eb"])
def test_look_alike_names_are_refused(peers, name):
    _session(peers, 2)
    peers[1].close()                       # "peer2" leaves; add a "bob"
    pump(peers, 0.1)
    join(peers, peers[0].tcp_address, "bob")
    if name in ("bob", "b\u043eb"):
        taken = "bob"
    else:
        taken = "host"
    with pytest.raises(NetError, match=f"looks like {taken}"):
        join(peers, peers[0].tcp_address, name, settle=False)


@pytest.mark.parametrize("name", [" ", "   ", " \u0301"])
def test_blank_names_are_refused(name):
    with pytest.raises(NetError, match="blank"):
        Peer(name)
    assert name_problem(name, []) is not None


@pytest.mark.parametrize("name", ["a\u200bb", "x\x1b[2J", "tab\t", "\u3000", "\u00ad"])
def test_unprintable_names_are_refused_before_connecting(name):
    with pytest.raises(NetError, match="printable"):
        Peer(name)


def test_blank_names_from_the_wire_are_refused_by_the_host(peers):
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    s = socket.create_connection(host.tcp_address, timeout=2)
    try:
        pump(peers, 0.05)
        s.recv(4096)
        s.sendall(P.encode(P.Join(" ", 1, 1, bytes(P.MAC_SIZE), host.digest), 0, 1, time.time()))
        pump(peers, 0.05)
        reader = P.StreamReader(Counter())
        msgs = reader.feed(s.recv(4096))
        assert isinstance(msgs[0].body, P.Refuse) and msgs[0].body.code == P.RefuseCode.NAME
        assert sorted(host.table) == [1]
    finally:
        s.close()


def test_name_keys():
    assert name_key("host") == name_key("hоst") == name_key("HOST") == name_key("ｈｏｓｔ")
    assert name_key("mike") == name_key("rnike") and name_key("alice") != name_key("bob")
    assert name_key("Zoë") == name_key("Zoe")


def test_refusal_text_is_shown_with_escapes_made_visible():
    """A hostile "host" refuses with escape sequences: the joiner's error shows them."""
    server = socket.socket()
    server.bind((LOOPBACK, 0))
    server.listen(1)

    def serve() -> None:
        conn, _ = server.accept()
        with conn:
            conn.sendall(P.encode(P.Challenge(bytes(P.NONCE_SIZE), False), 0, 1, time.time()))
            conn.recv(4096)
            conn.sendall(P.encode(P.Refuse(P.RefuseCode.FULL, "\x1b[2J\x1b]0;owned\x07gone\u202e"), 0, 2,
                                  time.time()))
            time.sleep(0.2)

    th = threading.Thread(target=serve, daemon=True)
    th.start()
    try:
        with pytest.raises(NetError) as err:
            Peer.join(server.getsockname(), "me", timeout=2.0, link_wait=0)
    finally:
        th.join(3)
        server.close()
    text = str(err.value)
    assert "\x1b" not in text and "\x07" not in text and "\u202e" not in text
    assert "\\x1b[2J" in text and "\\u202e" in text
    assert visible("a\\b\n") == "a\\\\b\\x0a"


# ---------------------------------------------------------------- the match digest
def test_peers_on_different_arenas_refuse_the_match(peers):
    box, fort = match_kw("box"), match_kw("fort")
    assert box["digest"] != fort["digest"] and box["digest"] == match_kw("box")["digest"]
    host = Peer.host((LOOPBACK, 0), "host", **box)
    peers.append(host)
    with pytest.raises(NetError, match="differs from the host's .*plays box"):
        join(peers, host.tcp_address, "other", settle=False, **fort)
    same = join(peers, host.tcp_address, "same", **box)
    assert same.number == 2
    assert host.dropped["refused_mismatch"] == 1


def test_the_digest_follows_the_bundle_files(tmp_path):
    import shutil

    from tanktool.net.digest import match_digest
    from tanktool.sim.match import load_match_arena, load_tank_spec

    copy = tmp_path / "box"
    shutil.copytree(load_match_arena("box").path, copy)
    spec = load_tank_spec("light")
    a = match_digest(load_match_arena(str(copy)), spec)
    assert a == match_digest(load_match_arena("box"), spec)
    with open(copy / "arena.toml", "a") as f:
        f.write("\n# edited\n")
    assert match_digest(load_match_arena(str(copy)), spec) != a
    assert match_digest(load_match_arena("box"), load_tank_spec("heavy")) != match_digest(load_match_arena("box"), spec)


# ---------------------------------------------------------------- Ctrl-C twice
def test_a_second_ctrl_c_while_the_host_shuts_down_still_writes_the_report(tmp_path):
    from tanktool.cli.net_play import run_network

    out = tmp_path / "host.json"
    lines: list[str] = []

    def echo(line: str) -> None:
        lines.append(line)
        if line.startswith("hosting on"):
            threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT)).start()     # the first Ctrl-C
        elif " s as player " in line:
            os.kill(os.getpid(), signal.SIGINT)           # the second, while the summary is printed
            time.sleep(0.05)

    report = run_network("127.0.0.1:0", None, "solo", None, "box", None, 30.0, 0, out, echo, bots=0)
    assert out.exists() and report["seconds"] < 10
    assert any(line.startswith("report:") for line in lines)


# ---------------------------------------------------------------- finding 8
def test_a_members_flood_is_dropped_before_decoding_and_honest_states_pass(peers, monkeypatch):
    """A member sends 600 valid-looking states at once (21,000 a second in the attack);
    the host drops all but its burst unread (no tag check, no decode), and takes every
    state of the honest member sent meanwhile."""
    from tanktool.net import peer as peer_mod

    _session(peers, 3)
    host, honest, flooder = peers
    decoded = Counter()
    real_decode = P.decode

    def counting(data, counter=None):
        decoded[data[4]] += 1                    # the sender byte
        return real_decode(data, counter)

    monkeypatch.setattr(peer_mod.P, "decode", counting)
    t = flooder.session_time()
    for k in range(600):
        flooder.send_state(P.State(flooder.number, t + k * 1e-4, 5.0, 5.0, 0, 0, 0, 0, 100, True))
        if k % 100 == 0:
            honest.send_state(P.State(honest.number, t + k * 1e-4, 7.0, 7.0, 0, 0, 0, 0, 100, True))
    events = []
    for _ in range(20):
        events += [(1, e) for e in host.poll(0.005)]
    assert states_from(events, 1, honest.number) == 6
    assert host.dropped["flood"] >= 600 - 2 * peer_mod.UDP_BURST
    assert decoded[flooder.number] <= 2 * peer_mod.UDP_BURST
