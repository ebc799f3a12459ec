"""Simulation speed: 8 tanks with their shells in each bundled arena, beside pymunk.

For every bundled arena (or, when none is bundled yet, a 120 m x 90 m box with a few
obstacles built here; 'hills' is terrain, 'fort' has two levels: tanks there stand on
the ground's surface, tilt with it and shells meet the model's triangles) this runs a
headless match of 8 scripted bots and times
``World.step`` alone and the whole match loop (bots deciding at 10 Hz included).  In
the same process, pymunk (Chipmunk2D, C) steps an equivalent scene: 8 box bodies of
the same size and mass driven by changing forces and torques inside 4 static walls.
The ratio column is our World.step rate over pymunk's.

Then 8 computer agents (sim/agents, ``--level``, default normal) drive the same arena: the CPU time of
their calls per world step, and the one-off time of their first think (each builds
its grid and sight map; cached per arena).

    python bench/sim.py [--steps N] [--seed K] [--level easy|normal|hard] [--json]
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.formats.walls_txt import WallList, aux_rectangle  # noqa: E402
from tanktool.sim.body import TankSpec  # noqa: E402
from tanktool.sim.driver import make_drivers  # noqa: E402
from tanktool.sim.match import default_vehicle, load_match_arena, load_tank_spec  # noqa: E402
from tanktool.sim.world import World  # noqa: E402


def _builtin_arena():
    walls = [[[60, 20], [60, 50]], [[20, 60], [40, 60]], [[40, 60], [40, 75]],
             [[85, 55], [100, 55]], [[100, 55], [100, 70]], [[100, 70], [85, 70]], [[85, 70], [85, 55]]]
    wl = WallList(np.array(walls, float), np.ones(len(walls), np.int8), aux_rectangle(0, 0, 120, 90))
    spawns = np.array([[10, 10, 0], [110, 10, math.pi], [10, 80, 0], [110, 80, math.pi],
                       [30, 30, 0.5], [90, 30, 2.5], [30, 45, -0.5], [75, 85, math.pi]], float)
    return "builtin-box", wl, spawns


def arenas():
    found = sorted(p.parent.name for p in (ROOT / "arenas").glob("*/walls.txt"))
    out = []
    for name in found:
        info = load_match_arena(ROOT / "arenas" / name)
        if len(info.spawns) >= 8:
            out.append((info.name, info.walls, info.spawns, info.ground, info.bounds))
    return out or [(*_builtin_arena(), None, None)]


def bench_ours(walls, spawns, spec: TankSpec, steps: int, seed: int, ground=None) -> dict:
    world = World(walls, [spec] * 8, spawns, seed=seed, ground=ground)
    drivers = make_drivers(world)
    tanks = world.tanks
    step_time = 0.0
    shells = 0
    t0 = time.perf_counter()
    for k in range(steps):
        cmds = [d(world, t) for d, t in zip(drivers, tanks)]
        s0 = time.perf_counter()
        world.step(None, cmds)
        step_time += time.perf_counter() - s0
        shells += len(world.shells)
    total = time.perf_counter() - t0
    return {"step_per_s": steps / step_time, "match_per_s": steps / total,
            "mean_shells": shells / steps, "shots": sum(t.shots for t in tanks)}


def bench_agents(walls, spawns, spec: TankSpec, steps: int, seed: int, ground=None, bounds=None,
                 level: str = "normal") -> dict:
    """8 computer agents (of ``level``) driving: CPU seconds in their calls per world
    step, after each has set up (its grid and sight map: timed apart, once per arena)."""
    from tanktool.sim.agents import make_agents

    world = World(walls, [spec] * 8, spawns, seed=seed, ground=ground, bounds=bounds)
    bots = make_agents(world, level)
    tanks = world.tanks
    s0 = time.process_time()
    cmds = [b(world, t) for b, t in zip(bots, tanks)]   # the first think sets each agent up
    setup = time.process_time() - s0
    world.step(None, cmds)
    spent = 0.0
    for _ in range(steps):
        s0 = time.process_time()
        cmds = [b(world, t) for b, t in zip(bots, tanks)]
        spent += time.process_time() - s0
        world.step(None, cmds)
    return {"agent_ms_per_step": 1000.0 * spent / steps, "agent_setup_s": setup}


def bench_pymunk(steps: int, seed: int, size=(120.0, 90.0), spec: TankSpec | None = None) -> dict | None:
    try:
        import pymunk
    except ImportError:
        return None
    spec = spec or TankSpec.box("box")
    rng = random.Random(seed)
    space = pymunk.Space()
    space.damping = 0.6
    W, H = size
    static = space.static_body
    for a, b in (((0, 0), (W, 0)), ((W, 0), (W, H)), ((W, H), (0, H)), ((0, H), (0, 0))):
        seg = pymunk.Segment(static, a, b, 0.1)
        seg.elasticity = 0.3
        space.add(seg)
    xs = [p[0] for p in spec.footprint]
    zs = [p[1] for p in spec.footprint]
    length, width = max(xs) - min(xs), max(zs) - min(zs)
    bodies = []
    for i in range(8):
        body = pymunk.Body(spec.mass, spec.inertia)
        body.position = (15 + (i % 4) * 28, 20 + (i // 4) * 45)
        body.angle = rng.uniform(-math.pi, math.pi)
        shape = pymunk.Poly.create_box(body, (length, width))
        shape.elasticity = 0.3
        shape.friction = 0.5
        space.add(body, shape)
        bodies.append(body)
    cmds = [(0.0, 0.0)] * 8
    dt = 1.0 / 120.0
    t0 = time.perf_counter()
    for k in range(steps):
        if k % 12 == 0:     # bots decide at 10 Hz here too
            cmds = [(rng.uniform(-0.5, 1.0), rng.uniform(-1, 1)) for _ in range(8)]
        for b, (a, r) in zip(bodies, cmds):
            b.apply_force_at_local_point((spec.engine_force * a, 0.0), (0.0, 0.0))
            b.torque = spec.turn_torque * r
        space.step(dt)
    total = time.perf_counter() - t0
    return {"step_per_s": steps / total, "version": pymunk.version}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=6000, help="steps per run (default 6000 = 50 s simulated)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--level", default="normal", choices=("easy", "normal", "hard"),
                    help="the computer agents' difficulty (default normal; hard thinks most often)")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    args = ap.parse_args(argv)
    vref = default_vehicle()
    spec = load_tank_spec(vref)
    peer = bench_pymunk(args.steps, args.seed, spec=spec)
    rows = []
    for name, walls, spawns, ground, bounds in arenas():
        ours = bench_ours(walls, spawns, spec, args.steps, args.seed, ground)
        agents = bench_agents(walls, spawns, spec, args.steps, args.seed, ground, bounds, args.level)
        rows.append({
            "arena": name,
            "levels": int(ground.levels) if ground is not None else 1,
            "relief": ground is not None,
            "walls": int(len(walls.all_segments())),
            "steps_per_s": round(ours["step_per_s"], 1),
            "match_steps_per_s": round(ours["match_per_s"], 1),
            "realtime_factor": round(ours["step_per_s"] / 120.0, 1),
            "mean_shells_in_flight": round(ours["mean_shells"], 2),
            "shots": ours["shots"],
            "pymunk_steps_per_s": round(peer["step_per_s"], 1) if peer else None,
            "ratio_to_pymunk": round(ours["step_per_s"] / peer["step_per_s"], 3) if peer else None,
            "agent_ms_per_step": round(agents["agent_ms_per_step"], 3),
            "agent_setup_s": round(agents["agent_setup_s"], 2),
        })
    result = {"benchmark": "sim", "tanks": 8, "vehicle": spec.name, "dt": 1 / 120, "steps": args.steps,
              "goal_steps_per_s": 2000, "goal_agent_ms_per_step": 1.0, "agent_level": args.level,
              "pymunk": peer["version"] if peer else None, "arenas": rows}
    if args.json:
        print(json.dumps(result))
        return 0
    print(f"8 tanks ({spec.name}), {args.steps} steps of 1/120 s, one core; pymunk {result['pymunk']} "
          "steps 8 boxes + 4 walls in the same run")
    head = (f"{'arena':<14} {'lv':>2} {'walls':>5} {'step/s':>8} {'match/s':>8} {'x real':>7} {'shells':>6} "
            f"{'pymunk/s':>9} {'ours/pymunk':>11} {'agents ms/step':>14} {'setup s':>7}")
    print(head)
    print("-" * len(head))
    for r in rows:
        pm = f"{r['pymunk_steps_per_s']:>9.0f}" if r["pymunk_steps_per_s"] else f"{'n/a':>9}"
        ratio = f"{r['ratio_to_pymunk']:>11.2f}" if r["ratio_to_pymunk"] else f"{'n/a':>11}"
        lv = f"{r['levels']}{'*' if r['relief'] else ''}"
        print(f"{r['arena']:<14} {lv:>2} {r['walls']:>5} {r['steps_per_s']:>8.0f} {r['match_steps_per_s']:>8.0f} "
              f"{r['realtime_factor']:>6.0f}x {r['mean_shells_in_flight']:>6.2f} {pm} {ratio} "
              f"{r['agent_ms_per_step']:>14.3f} {r['agent_setup_s']:>7.2f}")
    print(f"goal: >= {result['goal_steps_per_s']} steps/s with 8 tanks; computer agents < "
          f"{result['goal_agent_ms_per_step']:g} ms CPU per step for 8 ({args.level}, after setting up); "
          f"lv: levels, * on a ground (relief or levels)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
