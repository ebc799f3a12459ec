"""tanktool.env: PettingZoo's and Gymnasium's own checkers, the observation layout,
rewards from events with their weights, and determinism."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

pytest.importorskip("pettingzoo")
pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402
from pettingzoo.test import parallel_api_test, parallel_seed_test  # noqa: E402

import tanktool.env as te  # noqa: E402
from tanktool.env.core import Arena, EnvConfig, Episode, RewardWeights  # noqa: E402
from tanktool.errors import TanktoolError  # noqa: E402


def test_pettingzoo_parallel_api_test():
    parallel_api_test(te.parallel_env(agents=2, opponents=["easy"], seconds=4.0), num_cycles=200)


def test_pettingzoo_parallel_seed_test():
    parallel_seed_test(lambda: te.parallel_env(agents=2, opponents=["robot"], seconds=3.0), num_cycles=100)


def test_gymnasium_check_env():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")         # "no spec": made directly, not through gymnasium.make
        check_env(te.TankEnv(opponents=["novice"], seconds=3.0), skip_render_check=True)


def test_the_observation_is_the_documented_layout_in_its_space():
    env = te.parallel_env(agents=1, opponents=["camper"], seconds=2.0)
    obs, infos = env.reset(seed=3)
    o = obs["agent_0"]
    assert o.shape == (te.SIZE,) == (len(te.FIELDS),) and o.dtype == np.float32
    assert env.observation_space("agent_0").contains(o)
    f = dict(zip(te.FIELDS, o.tolist()))
    assert f["me.alive"] == 1.0 and f["me.hp"] == pytest.approx(1.0)
    assert f["me.cos_heading"] ** 2 + f["me.sin_heading"] ** 2 == pytest.approx(1.0, abs=1e-5)
    assert all(0.0 <= f[f"feeler{k}"] <= 1.0 for k in range(8))
    assert infos["agent_0"]["kills"] == 0


def _run(weights, seed=1, steps=800):
    cfg = EnvConfig(agents=1, opponents=("novice",), seconds=120.0, weights=weights)
    ep = Episode(cfg, Arena(cfg), seed)
    total = 0.0
    for _ in range(steps):
        # a scripted policy: turn onto what it sees and fire when lined up
        f = dict(zip(te.FIELDS, ep.observe(0).tolist()))
        seen = f["seen0.present"] > 0
        turn = float(np.clip(4.0 * f["seen0.right"], -1, 1)) if seen else 0.6
        fire = 1.0 if seen and abs(f["seen0.right"]) < 0.02 else -1.0
        r, _, _ = ep.step([(0.0 if seen else 0.3, turn, 0.0, fire)])
        total += r[0]
    return total, ep.world.tanks[0], ep.world.tanks[1]


def test_rewards_follow_the_events_and_their_weights():
    total, me, foe = _run(RewardWeights())
    w = RewardWeights()
    assert me.hits > 0       # the scripted policy hits the novice within 800 decisions
    assert total == pytest.approx(w.hit * me.hits + w.hurt * foe.hits + w.kill * me.kills + w.death * me.deaths)
    only_hits, me2, _ = _run(RewardWeights(hit=2.0, hurt=0.0, kill=0.0, death=0.0))
    assert me2.hits == me.hits and only_hits == pytest.approx(2.0 * me.hits)    # the same match: deterministic
    costs, _, foe3 = _run(RewardWeights(hit=0.0, hurt=-1.0, kill=0.0, death=-3.0, step=-0.01))
    assert costs == pytest.approx(-foe3.hits - 3.0 * me.deaths - 0.01 * 800)


def test_bad_setups_are_clear_errors():
    with pytest.raises(TanktoolError, match="spawn points"):
        te.parallel_env(agents=8, opponents=["easy"])
    with pytest.raises(TanktoolError, match="no such built-in bot"):
        te.TankEnv(opponents=["nobody"])
    with pytest.raises(TanktoolError, match="agents"):
        te.parallel_env(agents=0)


def test_the_example_runs_both_policies_and_plots(tmp_path):
    import runpy
    from pathlib import Path

    example = Path(__file__).resolve().parent.parent / "examples" / "env_policies.py"
    main = runpy.run_path(str(example))["main"]
    out = tmp_path / "returns.png"
    assert main(["--episodes", "1", "--seconds", "2", "--out", str(out)]) == 0
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_the_feelers_agree_with_the_walls_first_hit():
    import math

    from tanktool.env.observe import _FEELER_DIRS, FEELER, feelers
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.world import World

    rng = np.random.default_rng(0)
    for name in ("box", "fort"):
        info = load_match_arena(name)
        world = World(info.walls, [load_tank_spec("light")], info.spawns, bounds=info.bounds, ground=info.ground)
        for walls in [world.walls, *world.level_walls]:
            (x0, z0), (x1, z1) = world.bounds.tolist()
            for _ in range(60):
                x, z, h = rng.uniform(x0, x1), rng.uniform(z0, z1), rng.uniform(-math.pi, math.pi)
                c, s = math.cos(h), math.sin(h)
                want = []
                for dc, ds in _FEELER_DIRS:
                    fx, fz = c * dc - s * ds, s * dc + c * ds
                    hit = walls.first_hit(x, z, x + FEELER * fx, z + FEELER * fz)
                    want.append(1.0 if hit is None else max(hit[0], 0.0))
                assert feelers(walls, x, z, c, s) == pytest.approx(want, abs=1e-9)


def test_gymnasium_make_finds_it():
    import gymnasium

    env_id = te.register()
    env = gymnasium.make(env_id, opponents=["novice"], seconds=2.0)
    check_env(env.unwrapped, skip_render_check=True)
    obs, _ = env.reset(seed=1)
    assert obs.shape == (te.SIZE,)
    env.close()
