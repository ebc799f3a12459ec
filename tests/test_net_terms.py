"""Host terms (issue 27 finding 4): a host frozen longer than the silence comes back to
a session that elected another; it finds the newer term, steps down without keeping
copies of the computer opponents, and rejoins as a member; a joiner dialling its
address meanwhile is redirected, never taken into a split session."""

from __future__ import annotations

import socket
import threading
import time

import pytest

from net_helpers import LOOPBACK, join, peers, play, pump  # noqa: F401 (peers: the fixture)

from tanktool.errors import NetError
from tanktool.net import protocol as P
from tanktool.net.peer import Peer

SILENCE = 0.5


def _frozen_host_session(peers):
    host = Peer.host((LOOPBACK, 0), "host", silence=SILENCE)
    peers.append(host)
    assert host.add_bot("bot1") == 2
    for name in ("p3", "p4"):
        join(peers, host.tcp_address, name, silence=SILENCE)
    pump(peers, 0.1)
    assert host.term == 1 and all(p.term == 1 for p in peers)
    # the host freezes (SIGSTOP): only the members go on
    play(peers[1:], 1.5)
    return host, peers[1], peers[2]


def test_a_frozen_host_steps_down_and_rejoins_without_duplicate_bots(peers):
    host, a, b = _frozen_host_session(peers)
    assert a.is_host and a.number == 3 and a.term == 2 and b.term == 2
    assert a.table[2].owner == 3                           # the new host adopted the bot
    # SIGCONT: the old host reads its closed links, finds itself alone, probes
    events = play(peers, 1.0)
    steps = [e for who, e in events if who == 1 and e.kind == "stepdown"]
    assert steps and "term 2" in steps[0].reason, [e for who, e in events if who == 1]
    # the stale host sends a joiner on to the newer session
    newcomer = join(peers, host.tcp_address, "late", silence=SILENCE)
    assert newcomer.host_number == 3 and newcomer.term == 2
    # it rejoins as a member (blocking, like a join: the others are polled meanwhile)
    th = threading.Thread(target=host.rejoin, daemon=True)
    th.start()
    end = time.monotonic() + 8
    while th.is_alive() and time.monotonic() < end:
        play(peers[1:], 0.01)
    th.join(1)
    play(peers, 0.3)
    assert host.number not in (0, 1) and host.host_number == 3 and host.term == 2
    for p in peers:
        assert sorted(p.table) == sorted([2, 3, 4, newcomer.number, host.number]), (p.number, p.table)
        bots = [e for e in p.table.values() if e.is_bot]
        assert [(e.number, e.owner) for e in bots] == [(2, 3)]          # one copy, run by the new host
        assert p.host_number == 3
    assert not host.is_host and host.speaks_for() == [host.number]


def test_terms_travel_in_challenges_and_tables():
    c = P.decode(P.encode(P.Challenge(bytes(16), True, 7, 3, 5), 0, 1, 1.0))
    assert (c.body.term, c.body.host, c.body.players) == (7, 3, 5)
    table = P.Table(1, (P.Entry(1, 1, "127.0.0.1", 5, 5, "h"),))
    m = P.decode(P.encode(P.Assign(1, 2.0, table, 9), 1, 1, 1.0, kind=P.MessageType.TABLE))
    assert m.body.term == 9


def test_a_member_alone_after_a_crash_of_everyone_takes_joins_again(peers):
    """Losing everyone to a crash (nobody answers the probes) delays joins only for
    one round of probes."""
    host = Peer.host((LOOPBACK, 0), "host", silence=SILENCE)
    peers.append(host)
    b = join(peers, host.tcp_address, "b", silence=SILENCE)
    b.close(send_exit=False)                # its sockets close: nobody will answer there
    pump(peers, 0.3)
    late = join(peers, host.tcp_address, "late", silence=SILENCE)
    assert late.host_number == 1 and host.step_down_to is None


class _Runner:
    """A NetMatch pumped by its own thread (one process each, as in real play);
    ``frozen`` set stops it like SIGSTOP."""

    def __init__(self, match) -> None:
        self.match = match
        self.frozen = threading.Event()
        self.done = threading.Event()
        self.error = None
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.match.begin()
        self.thread.start()

    def _run(self) -> None:
        try:
            while not self.done.is_set() and not self.match.stop:
                if self.frozen.is_set():
                    time.sleep(0.01)
                    continue
                self.match.pump(until=time.monotonic() + 0.01)
        except Exception as e:          # handed to the test thread
            self.error = e

    def finish(self) -> dict:
        self.done.set()
        self.thread.join(10)
        if self.error is not None:
            raise self.error
        return self.match.finish()


def test_a_frozen_host_match_rejoins_and_its_bots_are_not_duplicated(peers):
    from tanktool.net.session import NetMatch
    from tanktool.sim.match import load_match_arena, load_tank_spec

    info, spec = load_match_arena("box"), load_tank_spec("light")
    host = Peer.host((LOOPBACK, 0), "host", silence=SILENCE)
    peers.append(host)
    hm = NetMatch(host, info, spec, seed=1, bots=1)
    runners = [_Runner(hm)]
    try:
        for name in ("p3", "p4"):
            # (nobody else polls here: the host's own thread answers the join)
            p = join([], host.tcp_address, name, silence=SILENCE, settle=False)
            peers.append(p)
            runners.append(_Runner(NetMatch(p, info, spec, seed=1)))
        time.sleep(0.5)
        runners[0].frozen.set()               # SIGSTOP
        time.sleep(1.5)
        runners[0].frozen.clear()             # SIGCONT
        deadline = time.monotonic() + 10
        while not hm.rejoins or "number" not in hm.rejoins[-1]:
            assert time.monotonic() < deadline, "the old host never rejoined"
            time.sleep(0.05)
        time.sleep(1.0)
    finally:
        reports = [r.finish() for r in runners]
    old, a, b = reports
    assert old["rejoined"][0]["old_number"] == 1 and old["me"] not in (1, 2, 3, 4)
    for rep in reports:
        assert rep["host"] == 3 and rep["term"] == 2
        bots = [p for p in rep["peers"] if p["bot"]]
        assert [(p["number"], p["run_by"]) for p in bots] == [(2, 3)]
        assert sorted(p["number"] for p in rep["peers"]) == sorted([2, 3, 4, old["me"]])


def test_a_failed_rejoin_hosts_alone_again_on_the_same_ports(peers):
    """The session a probe found is gone by the time we rejoin: NetError says why, and
    the peer hosts its own session again on its ports, still probing, not in no session."""
    host = Peer.host((LOOPBACK, 0), "host", silence=SILENCE)
    peers.append(host)
    where = host.tcp_address
    with socket.socket() as s:                      # a port where nobody listens
        s.bind((LOOPBACK, 0))
        gone = s.getsockname()
    with pytest.raises(NetError, match="cannot reach"):
        host.rejoin(gone, timeout=1.0)
    assert host.is_host and host.number == 1 and host.tcp_address == where
    newcomer = join(peers, where, "late", silence=SILENCE)
    assert newcomer.host_number == 1 and newcomer.number == 2
