"""A cheating member against a real host (finding 6 of issue 27, end to end on
loopback): teleports, a position 5 km outside the arena, 100 m/s, 100 shots a second
from beside the victim, shots while dead, made-up hit points and fake "player 1 killed
me" HITs.  The host's view never leaves what the cheater's vehicle could have done,
nothing the cheater claims about others counts, and after 5 s of corrections the host
disconnects it."""

from __future__ import annotations

import math
import time

from net_helpers import LOOPBACK, join, peers  # noqa: F401 (peers: the fixture)

from tanktool.net import protocol as P
from tanktool.net.peer import Peer
from tanktool.net.session import NetMatch
from tanktool.sim.match import load_match_arena, load_tank_spec


def test_a_cheater_is_judged_by_the_host_and_disconnected(peers):
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    info, spec = load_match_arena("box"), load_tank_spec("light")
    match = NetMatch(host, info, spec, seed=3)
    match.begin()
    cheat = join(peers, host.tcp_address, "cheat", settle=False)
    peers.append(cheat)
    n = cheat.number
    honest_end = time.monotonic() + 0.5
    end = time.monotonic() + 9.0
    k = 0
    positions = []
    while time.monotonic() < end and not cheat.closed:
        match.pump(until=time.monotonic() + 0.01)
        t = cheat.session_time()
        k += 1
        if time.monotonic() < honest_end:
            s = P.State(n, t, 20.0, 20.0, 0.0, 0.0, 0.0, 0.0, 100.0, True)     # standing still: fine
        else:
            x, z, v = [(45.0, 45.0, 0.0), (5000.0, 10.0, 0.0), (20.0, 20.0, 100.0), (10.0, 50.0, 0.0)][k % 4]
            s = P.State(n, t, x, z, 0.0, v, 0.0, 0.0, 60000.0, True)
            me = match.me
            cheat.send_event(P.Shot(n, t, me.x + 5.0, me.z, 0.0, 0.0, 0.0))       # beside the victim
            cheat.send_event(P.Hit(1, n, t, 100.0, 0.0, True, 20.0, 20.0))        # "player 1 killed me"
        cheat.send_state(s)
        cheat.poll(0)
        tank = match.world.tanks[n - 1]
        if tank.alive:
            positions.append((tank.x, tank.z, tank.hp))
    report = match.finish()
    judge = report["judge"]
    # the view: always inside the box, never faster than the vehicle, hit points its own
    assert positions and all(0 <= x <= 60 and 0 <= z <= 60 and hp <= spec.hit_points for x, z, hp in positions)
    for (x0, z0, _), (x1, z1, _) in zip(positions, positions[1:]):
        assert math.hypot(x1 - x0, z1 - z0) < 3.0
    assert sum(judge["corrected"].values()) > 100
    # its shots: refused (from afar), and the shells it got launched hit nobody
    assert judge["shots_refused"].get("pose", 0) + judge["shots_refused"].get("reload", 0) > 50
    assert match.scores.get(1) is None or match.scores[1].deaths == 0
    assert match.world.tanks[0].hp == spec.hit_points
    # its HITs about player 1: dropped, no kills for anyone
    assert host.dropped["not_host"] > 50
    assert all(s.kills == 0 for s in match.scores.values())
    # disconnected after seconds of corrections, and never back in the table
    assert [x["number"] for x in judge["kicked"]] == [n]
    assert n not in host.table and cheat.closed


def test_a_respawned_member_is_protected_at_the_host_as_in_its_own_world(peers):
    """The host decides hits, so it must give a member's respawned tank the spawn
    protection the member's own world gives it (and end it when it fires)."""
    from tanktool.net.peer import NetEvent

    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    match = NetMatch(host, load_match_arena("box"), load_tank_spec("light"), seed=3)
    w = match.world
    host.table[2] = P.Entry(2, 2, LOOPBACK, 40001, 40001, "member")
    host.window.anchor(2, 0, host.clock())
    sent = iter(range(1, 100))

    def state(s: P.State) -> None:        # a state as the core takes it (and judges it)
        now = host.clock()
        assert host.core._on_state(P.Message(P.MessageType.STATE, 2, next(sent), now, s), now)
        match._on_net(host.core.take_events())

    sx, sz, _ = w.spawns[1]
    t = host.session_time()
    state(P.State(2, t, 20.0, 20.0, 0, 0, 0, 0, 0, True))
    match.judge.hit(2, 0.0, True, t)                      # the host killed it
    w.protected_until[1] = -math.inf                      # (it had fired before)
    t += w.respawn_delay + 0.1
    host.session_offset -= w.respawn_delay + 0.1          # the session clock moves on as much
    w.t = t
    state(P.State(2, t, sx, sz, 0, 0, 0, 0, 0, True))
    assert match.judge.alive(2) and w.protected_until[1] > w.t
    match._on_net([NetEvent("shot", 2, P.Shot(2, t + 0.01, sx, sz, 0.0, 0.0, 0.0))])
    assert w.protected_until[1] == -math.inf
