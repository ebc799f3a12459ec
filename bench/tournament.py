"""Tournament and environment throughput (issue 31).

Tournament: the same round robin (4 bots -- novice, easy, robot and the bot written
from docs/bots.md, tests/data/bots/hunter.py -- 6 pairings x --matches duels of
--seconds on the box) played serially in this process (the peer), on a local pool of
--workers processes and on a local Ray cluster of --workers CPUs.  Printed: matches
per second, the speed-up over serial, and the overhead per match: the wall clock the
runner spent beyond the matches' own time (wall x workers - the matches' summed time,
per match; serial: wall - summed time).  Ray's start-up is timed apart.  The reports
are checked identical (timing apart).

Environment: env steps per second (``tanktool.env.parallel_env``, 4 simulation steps
per env step) for 1 learning agent against an ``easy`` bot and for 8 learning agents
alone, on the box and the hills, random actions; beside it, in the same process, the
bare simulation of the same tanks stepped with the same commands (the peer): the
ratio is the cost of perception, observations and rewards.  Goal: >= 1,000
single-agent steps/s on the box.

    python bench/tournament.py [--matches 2] [--seconds 10] [--workers 2] [--env-seconds 3]
                               [--no-ray] [--json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.tournament import TournamentConfig, run_tournament  # noqa: E402

BOTS = ("novice", "easy", "robot", str(ROOT / "tests" / "data" / "bots" / "hunter.py") + ":Hunter")
GOAL = 1000.0


def _plain(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "timing"}


def bench_tournament(matches: int, seconds: float, workers: int, use_ray: bool) -> dict:
    config = TournamentConfig(bots=BOTS, matches=matches, seconds=seconds, boot=100)
    rows = []
    reports = {}
    runs = [("serial", 1), ("pool", workers)] + ([("ray", workers)] if use_ray else [])
    ray_start = None
    for run, n in runs:
        if run == "ray":
            import ray

            t0 = time.perf_counter()
            ray.init(num_cpus=n, include_dashboard=False, log_to_driver=False, configure_logging=False)
            ray_start = time.perf_counter() - t0
            run_tournament(TournamentConfig(bots=BOTS[:2], matches=1, seconds=0.5, boot=0), run="ray",
                           workers=n, record=False)      # workers up and the code shipped before the clock
        t0 = time.perf_counter()
        t = run_tournament(config, run=run, workers=n)
        wall = time.perf_counter() - t0
        reports[run] = t.report
        k = len(t.report["matches"])
        busy = t.report["timing"]["match_s_total"]
        rows.append({"runner": run, "workers": n, "matches": k, "wall_s": round(wall, 3),
                     "matches_per_s": round(k / wall, 3), "match_s_total": busy,
                     "overhead_ms_per_match": round(1000.0 * (wall * n - busy) / k, 1)})
    base = rows[0]["matches_per_s"]
    for r in rows:
        r["speedup"] = round(r["matches_per_s"] / base, 2)
    same = all(_plain(reports[r]) == _plain(reports["serial"]) for r in reports)
    if use_ray:
        import ray

        ray.shutdown()
    return {"bots": list(BOTS), "arena": "box", "matches_per_pairing": matches, "seconds_per_match": seconds,
            "runs": rows, "identical_reports": same,
            "ray_start_s": None if ray_start is None else round(ray_start, 2)}


def bench_env(arena: str, agents: int, opponents: list[str], budget: float) -> dict:
    import tanktool.env as te

    env = te.parallel_env(arena=arena, agents=agents, opponents=opponents, seconds=3600.0)
    env.reset(seed=1)
    rng = np.random.default_rng(0)
    acts = [{a: rng.uniform(-1, 1, 4).astype(np.float32) for a in env.possible_agents} for _ in range(64)]
    for k in range(30):                              # warm up: grids and sight tables built once per arena
        env.step(acts[k % 64])
    ep = env.episode
    k, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < budget:
        env.step(acts[k % 64])
        k += 1
    env_rate = k / (time.perf_counter() - t0)
    # the peer: the same world stepped with the same commands, opponents driven, nothing observed
    from tanktool.env.core import command_of

    w = ep.world
    n = agents
    cmds = [[command_of(a[p]) for p in env.possible_agents] for a in acts]
    j, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < budget:
        learn = cmds[j % 64]
        for _ in range(ep.config.action_repeat):
            w.step(None, learn + [d(w, t) for d, t in zip(ep.opponents, w.tanks[n:])])
        j += 1
    sim_rate = j / (time.perf_counter() - t0)
    return {"arena": arena, "agents": agents, "opponents": opponents, "env_steps_per_s": round(env_rate, 1),
            "agent_steps_per_s": round(env_rate * agents, 1), "sim_only_steps_per_s": round(sim_rate, 1),
            "env_over_sim": round(env_rate / sim_rate, 3)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--matches", type=int, default=2)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--env-seconds", type=float, default=3.0, help="wall seconds per env measurement")
    ap.add_argument("--no-ray", action="store_true")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    use_ray = not args.no_ray
    if use_ray:
        try:
            import ray  # noqa: F401
        except ImportError:
            use_ray = False
    out = {"tournament": bench_tournament(args.matches, args.seconds, args.workers, use_ray)}
    envs = []
    for arena in ("box", "hills"):
        envs.append(bench_env(arena, 1, ["easy"], args.env_seconds))
        envs.append(bench_env(arena, 8, [], args.env_seconds))
    out["env"] = envs
    box1 = next(e for e in envs if e["arena"] == "box" and e["agents"] == 1)
    out["goal"] = {"goal": f">= {GOAL:g} single-agent env steps/s on the box", "value": box1["env_steps_per_s"],
                   "met": box1["env_steps_per_s"] >= GOAL}
    if args.json:
        print(json.dumps(out))
        return 0
    t = out["tournament"]
    print(f"tournament: {len(BOTS)} bots, {t['matches_per_pairing']} x {t['seconds_per_match']:g} s duels per "
          f"pairing on the box")
    print(f"{'runner':<8} {'workers':>7} {'matches':>7} {'wall s':>8} {'matches/s':>10} {'speed-up':>9} "
          f"{'overhead ms/match':>18}")
    for r in t["runs"]:
        print(f"{r['runner']:<8} {r['workers']:>7} {r['matches']:>7} {r['wall_s']:>8.2f} {r['matches_per_s']:>10.2f} "
              f"{r['speedup']:>8.2f}x {r['overhead_ms_per_match']:>18.1f}")
    if t["ray_start_s"] is not None:
        print(f"Ray cluster start-up: {t['ray_start_s']:.1f} s (once)")
    print(f"reports identical across runners: {t['identical_reports']}")
    print()
    print(f"{'arena':<7} {'agents':>6} {'opponents':<10} {'env steps/s':>12} {'agent steps/s':>14} "
          f"{'sim only/s':>11} {'env/sim':>8}")
    for e in envs:
        print(f"{e['arena']:<7} {e['agents']:>6} {','.join(e['opponents']) or '-':<10} {e['env_steps_per_s']:>12.0f} "
              f"{e['agent_steps_per_s']:>14.0f} {e['sim_only_steps_per_s']:>11.0f} {e['env_over_sim']:>8.2f}")
    g = out["goal"]
    print(f"{'met' if g['met'] else 'NOT MET'}: {g['goal']}: {g['value']:.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
