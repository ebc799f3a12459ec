"""A tank stands where it stops on a ramp (issue 28, the generated bridge).

Traced on the gen-bridge at seed 0 (0-0 in every pairing): hard spawned at the top of
the west ramp, 0.5 m inside the ramp's side, and slid to the ramp's foot while the
robot stood on the far plateau 5 m up.  Two causes, both the ground's:

* the hull's tilt read the ground at its back over the cell beside the ramp's side (no
  surface: read as 0): pitched 41 degrees at the start, and gravity along that pitch
  pulled it off (``ground.supported``: an end over a drop does not carry the hull);
* nothing held a tank stopped on a slope: it crept sideways down the ramp at
  0.36 m/s against its tracks' grip and rolled back down it, to the ramp's side in
  10 s, then over it (``on_ground.slope_pull``: the tracks hold it).
"""

from __future__ import annotations

import math

import pytest

from tanktool.bots import load_bot
from tanktool.sim.commands import IDLE, Command
from tanktool.sim.ground import supported
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match
from tanktool.sim.world import World

RAMP = 18.5     # the bridge's ramps: 5 m up over 15 m [degrees]


@pytest.fixture(scope="module")
def bridge(imported_level):
    return load_match_arena(imported_level("bridge"))


def _world(info, spawn):
    spec = load_tank_spec("light")
    return World(info.walls, [spec], [spawn], seed=0, bounds=info.bounds, ground=info.ground)


def test_an_end_over_a_drop_does_not_carry_the_hull():
    assert supported(5.0, 5.0, 0.0, 3.0) == (5.0, 5.0)          # level, its back over a drop
    assert supported(4.0, 4.5, 0.0, 3.0) == (4.5, 3.5)          # on the front's slope
    assert supported(5.0, 0.0, 0.0, 3.0) == (5.0, 5.0)          # on a ridge: level
    assert supported(1.0, 2.0, 0.0, 3.0) == (2.0, 0.0)          # a slope, not a drop


def test_a_tank_parked_at_every_spawn_of_the_bridge_stays_there(bridge):
    spec = load_tank_spec("light")
    on_ramp = 0
    for spawn in bridge.spawns_for(spec):
        w = _world(bridge, spawn)
        t = w.tanks[0]
        x0, z0 = t.x, t.z
        assert abs(t.pitch) < math.radians(RAMP) and abs(t.roll) < math.radians(RAMP), spawn
        on_ramp += abs(t.pitch) + abs(t.roll) > math.radians(3.0)
        for _ in range(int(10.0 / w.dt)):
            w.step(None, [IDLE])
            assert abs(t.pitch) < math.radians(RAMP) and abs(t.roll) < math.radians(RAMP), spawn
        assert math.hypot(t.x - x0, t.z - z0) < 0.1, spawn
    assert on_ramp >= 1      # the case traced: a spawn at a ramp's top


def test_a_tank_stopped_on_the_ramp_stays_and_one_driven_down_it_goes(bridge):
    for heading in (-0.5 * math.pi, 0.0, 0.7):     # down the ramp, across it, askew
        w = _world(bridge, (8.0, 9.0, heading))
        t = w.tanks[0]
        w.stand(t, None)
        assert t.y < 4.0 and abs(t.pitch) + abs(t.roll) > math.radians(10.0)      # on the ramp
        x0, z0 = t.x, t.z
        for _ in range(int(3.0 / w.dt)):
            w.step(None, [IDLE])
        assert math.hypot(t.x - x0, t.z - z0) < 0.1, heading
    # a pilot braking to a stop commands a little against the way it goes: held
    w = _world(bridge, (8.0, 9.0, -0.5 * math.pi))
    t = w.tanks[0]
    w.stand(t, None)
    z0 = t.z
    for _ in range(int(5.0 / w.dt)):
        w.step(None, [Command(advance=-0.3 * (t.vx * t.c + t.vz * t.s) - 0.01)])
    assert abs(t.z - z0) < 0.1, t.z - z0
    # a little of the command up it is not a crawl up what it cannot climb
    w = _world(bridge, (8.0, 9.0, 0.5 * math.pi))
    t = w.tanks[0]
    w.stand(t, None)
    z0 = t.z
    for _ in range(int(3.0 / w.dt)):
        w.step(None, [Command(advance=0.25)])
    assert t.z < z0
    w = _world(bridge, (8.0, 9.0, -0.5 * math.pi))
    t = w.tanks[0]
    w.stand(t, None)
    for _ in range(int(2.0 / w.dt)):
        w.step(None, [Command(advance=1.0)])
    assert 9.0 - t.z > 3.0


def test_hard_spawned_at_the_ramp_top_does_not_end_at_its_foot(bridge):
    """The ladder's duel 0 on the bridge (hard tank 0, the robot tank 1): hard stays up
    on the plateau's level for its first 20 s (it was at 2 m, down the ramp, in 12 s)."""
    spec = load_tank_spec("light")
    makers = [load_bot("hard"), load_bot("robot")]
    lowest = [math.inf]

    def wrap(world, _made):
        seeds = [world.rng.getrandbits(64) for _ in world.tanks]
        drivers = [m.driver(s) for m, s in zip(makers, seeds)]

        def watched(w, t, d=drivers[0]):
            if t.alive and w.t > 0.5:
                lowest[0] = min(lowest[0], t.y)
            return d(w, t)
        return [watched, drivers[1]]

    run_match(bridge, spec, bots=2, seconds=20.0, seed=0, bot="scripted", wrap_drivers=wrap)
    assert lowest[0] > 4.0, lowest[0]
