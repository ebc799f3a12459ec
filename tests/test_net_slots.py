"""A network session seats the tanks its arena holds (issue 25): the host takes the
arena's capacity (spawn points and free places, sim/extra_spawns.py) as its number of
slots, refuses joiners beyond it with a reason naming it, and an arena holding fewer
than the protocol's 8 tanks still hosts a smaller session."""

from __future__ import annotations

import numpy as np
import pytest
from net_helpers import LOOPBACK, join, peers, pump  # noqa: F401  (peers: a fixture)

from tanktool.errors import NetError
from tanktool.formats.walls_txt import read_walls
from tanktool.net import protocol as P
from tanktool.net.peer import Peer
from tanktool.net.session import NetMatch
from tanktool.sim.extra_spawns import holds, slots
from tanktool.sim.flat_ground import FlatGround
from tanktool.sim.match import ArenaInfo, load_match_arena, load_tank_spec


def _room(tmp_path, size: float = 14.0) -> ArenaInfo:
    """A bare square room with one spawn point: 4 light tanks fit in it at once."""
    p = tmp_path / "walls.txt"
    s = size
    p.write_text(f"0 0 {s} 0 1\n{s} 0 {s} {s} 1\n{s} {s} 0 {s} 1\n0 {s} 0 0 1\n")
    b = np.array([[0.0, 0.0], [s, s]])
    return ArenaInfo("room", read_walls(p), np.array([[3.0, 3.0, 0.0]]), None, b, FlatGround(b))


def test_slots_are_the_arena_capacity_up_to_the_protocol(tmp_path):
    light = load_tank_spec("light")
    room = _room(tmp_path)
    assert holds(room, [light], 8) == [("light", 4)]
    assert slots(room, light, P.MAX_PLAYERS) == 4
    assert slots(load_match_arena("maze"), light, P.MAX_PLAYERS) == P.MAX_PLAYERS


def test_a_four_tank_arena_hosts_four_players_and_refuses_the_fifth(tmp_path, peers):  # noqa: F811
    room, light = _room(tmp_path), load_tank_spec("light")
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    match = NetMatch(host, room, light, seed=1, bots=1)     # 8 slots would not fit: ArenaError before
    assert host.slots == 4 and len(match.world.tanks) == 4
    members = [join(peers, host.tcp_address, f"peer{k}") for k in (2, 3)]
    pump(peers, 0.2)
    assert sorted(host.table) == [1, 2, 3, 4]               # host, its bot, two members
    assert sorted(m.number for m in members) == [3, 4]
    with pytest.raises(NetError, match=r"session full: 4 players already \(the arena holds 4 tanks at once\)"):
        join(peers, host.tcp_address, "peer5", settle=False)
    # each member's own match seats as many, and places its tank in its slot
    for m in members:
        mm = NetMatch(m, room, light, seed=2)
        assert m.slots == 4 and mm.me is mm.world.tanks[m.number - 1]


def test_more_bots_than_the_arena_holds_is_refused_naming_it(tmp_path, peers):  # noqa: F811
    host = Peer.host((LOOPBACK, 0), "host")
    peers.append(host)
    with pytest.raises(NetError, match=r"arena room holds 4 tanks of light at once: not 5"):
        NetMatch(host, _room(tmp_path), load_tank_spec("light"), seed=1, bots=4)
    with pytest.raises(NetError, match=r"holds 1 tank of heavy at once: a network match needs 2"):
        NetMatch(host, _room(tmp_path), load_tank_spec("heavy"), seed=1)


@pytest.mark.parametrize("arena", ["box", "fort", "hills", "maze"])
def test_the_capacity_shortcut_counts_what_the_picks_find(arena, tmp_path):
    """capacity() skips the farthest-point picks when no set of discs of a tank's length
    round the spawns and picks could cover the candidates; it must say what picking
    them says, with the shortcut taken (limit 64) and not (a limit of hundreds)."""
    from tanktool.sim import extra_spawns
    from tanktool.sim.world import World

    info = load_match_arena(arena)
    for name in ("light", "heavy"):
        spec = load_tank_spec(name)
        own = info.spawns_for(spec)
        w = World(info.walls, [spec], own[:1], bounds=info.bounds, ground=info.ground)
        w.spawns = [tuple(map(float, r[:3])) for r in np.asarray(own, dtype=np.float64).reshape(len(own), -1)]
        length = spec.box[2] - spec.box[0]
        for limit in (16, 64, 400):
            picked = len(w.spawns) + len(extra_spawns.places(w, limit - len(w.spawns), spec.radius, length))
            assert extra_spawns.capacity(w, spec.radius, length, limit) == picked
