"""Matches on large terrains: steps per second and peak memory beside the box arena.

Runs ``tanktool play --headless``'s match (8 computer agents, ``--seconds`` simulated,
``--seed``) on the bundled box arena and on each terrain bundle given, each in its own
child process so every peak is that match's alone (the kernel's high-water mark,
VmHWM, from exec).  A child also times and sizes its phases: loading the bundle, the
first think of the agents (their layered grid: ``layers.clear_enough`` and
``ground_agent_grid``; the SolidField of sight), and the match loop; the memory
column of a phase is the resident size it added at its peak (a sampler thread reads
VmRSS every few milliseconds).

The terrains come from ``bench/import_arena.py``'s scale series (``terrain(size)``, a
rolling terrain at 2 m) imported at the default 0.5 m: ``--make 1000,2000 --cache DIR``
writes the OBJ and imports them into DIR once (a 2 km import takes about a minute and
3 GB) and reuses them.

    python bench/match_scale.py --cache /tmp/match [--make 1000,2000] [--arena PATH ...]
                                [--seconds 20] [--bots 8] [--seed 1] [--repeat 1] [--json]

``--repeat N`` runs every match N times, the arenas in turn, and keeps each arena's
fastest run (and its highest peak): on the shared machine a busy spell moved the
terrain's ratio to the box by 2x between two runs.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tools"))

#: (phase, "module:qualified name") timed and sized in the child, outermost first
HOOKS = [
    ("load", "tanktool.sim.match:load_match_arena"),
    ("clearance", "tanktool.sim.agents.layers:clear_enough"),
    ("agent grid", "tanktool.sim.agents.layers:ground_agent_grid"),
    ("solid field", "tanktool.sim.ground:SolidField.__init__"),
]


def _status(key: str) -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key):
            return int(line.split()[1]) / 1024
    return 0.0


class Sampler:
    """The highest VmRSS seen since :meth:`reset` (MB), read every ``period`` s."""

    def __init__(self, period: float = 0.003) -> None:
        self.period, self.peak = period, 0.0
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self) -> None:
        while True:
            self.peak = max(self.peak, _status("VmRSS:"))
            time.sleep(self.period)

    def reset(self) -> float:
        now = _status("VmRSS:")
        self.peak = now
        return now


def _hook(phases: dict, sampler: Sampler, name: str, spec: str) -> None:
    import importlib

    mod_name, qual = spec.split(":")
    obj: Any = importlib.import_module(mod_name)
    parts = qual.split(".")
    for p in parts[:-1]:
        obj = getattr(obj, p)
    fn: Callable = getattr(obj, parts[-1])

    def wrapped(*a: Any, **k: Any) -> Any:
        outer = sampler.peak   # an enclosing phase's peak so far (nested hooks)
        before = sampler.reset()
        t0 = time.perf_counter()
        try:
            return fn(*a, **k)
        finally:
            peak = max(sampler.peak, _status("VmRSS:"))
            row = phases.setdefault(name, {"seconds": 0.0, "added_mb": 0.0, "peak_mb": 0.0, "calls": 0})
            row["seconds"] += time.perf_counter() - t0
            row["added_mb"] = max(row["added_mb"], peak - before)
            row["peak_mb"] = max(row["peak_mb"], peak)
            row["calls"] += 1
            sampler.peak = max(outer, peak)

    setattr(obj, parts[-1], wrapped)
    # modules that imported the function by name
    for m in list(sys.modules.values()):
        if m is not None and getattr(m, parts[-1], None) is fn and m is not obj:
            setattr(m, parts[-1], wrapped)


def child(arena: str, bots: int, seconds: float, seed: int) -> dict:
    """One match in this process: phases, steps/s, peak (see the module docstring)."""
    import tanktool.sim.agents.layers  # noqa: F401  (hooked below)
    import tanktool.sim.agents.navigation  # noqa: F401
    from tanktool.sim import match

    sampler = Sampler()
    phases: dict = {}
    for name, spec in HOOKS:
        _hook(phases, sampler, name, spec)
    base = _status("VmRSS:")
    info = match.load_match_arena(arena)
    spec = match.load_tank_spec(match.choose_vehicle(info, None, lambda *_: None)
                                if hasattr(match, "choose_vehicle") else match.default_vehicle())
    ticks: list[float] = []   # when each step ended
    cpu: list[float] = []     # the process's CPU seconds then (steadier than the wall on a shared machine)
    t0 = time.perf_counter()

    def tick(_n: int) -> None:
        ticks.append(time.perf_counter())
        if len(cpu) < 2:
            cpu.append(time.process_time())
        else:
            cpu[1] = time.process_time()

    result = match.run_match(info, spec, bots=bots, seconds=seconds, seed=seed, on_progress=tick, progress_every=1)
    timing = result.report["timing"]
    after = (len(ticks) - 1) / (ticks[-1] - ticks[0]) if len(ticks) > 1 and ticks[-1] > ticks[0] else None
    after_cpu = (len(ticks) - 1) / (cpu[1] - cpu[0]) if len(cpu) > 1 and cpu[1] > cpu[0] else None
    return {"arena": info.name, "nodes": _nodes(info), "steps": result.report["steps"],
            "steps_per_second": timing["steps_per_second"], "wall_s": timing["wall_clock_s"],
            "after_first_steps_per_second": round(after, 1) if after else None,
            "after_first_steps_per_cpu_second": round(after_cpu, 1) if after_cpu else None,
            "first_step_s": round(ticks[0] - t0, 3) if ticks else None, "prepare_s": timing.get("prepare_s"),
            "base_mb": round(base, 1),
            "peak_mb": round(_status("VmHWM:"), 1),
            "phases": {k: {"seconds": round(v["seconds"], 3), "added_mb": round(v["added_mb"], 1),
                           "peak_mb": round(v["peak_mb"], 1), "calls": v["calls"]} for k, v in phases.items()}}


def _nodes(info: Any) -> int | None:
    g = getattr(info, "ground", None)
    return int(g.exists.sum()) if getattr(g, "relief", False) else None


def run_child(arena: str, a: argparse.Namespace) -> dict:
    cmd = [sys.executable, __file__, "--child", arena, "--bots", str(a.bots), "--seconds", str(a.seconds),
           "--seed", str(a.seed)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout)
    if proc.returncode != 0:
        return {"arena": arena, "error": (proc.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def best_of(arenas: list[str], a: argparse.Namespace) -> list[dict]:
    """Each arena's match ``--repeat`` times, the arenas in turn (a busy spell of the
    shared machine falls on all of them alike), each arena's fastest run kept (its
    steps/s figures, the fastest of each) with the highest peak of its runs."""
    runs: list[list[dict]] = [[] for _ in arenas]
    for _ in range(max(a.repeat, 1)):
        for k, ar in enumerate(arenas):
            runs[k].append(run_child(ar, a))
    rows = []
    for ar, got in zip(arenas, runs):
        ok = [r for r in got if "error" not in r]
        if not ok:
            rows.append(got[0])
            continue
        best = dict(max(ok, key=lambda r: r["steps_per_second"] or 0))
        for key in ("after_first_steps_per_second", "after_first_steps_per_cpu_second"):
            vals = [r[key] for r in ok if r.get(key)]
            best[key] = max(vals) if vals else None
        best["peak_mb"] = max(r["peak_mb"] for r in ok)
        best["runs"] = len(ok)
        rows.append(best)
    return rows


def make_terrains(sizes: list[float], cache: Path) -> list[str]:
    """Import the scale series' terrain of each size into ``cache`` once (see the docstring)."""
    import import_arena

    out = []
    cache.mkdir(parents=True, exist_ok=True)
    for size in sizes:
        bundle = cache / f"t{size:g}"
        if not (bundle / "arena.toml").is_file():
            obj = import_arena.terrain(size, cache)
            subprocess.run([sys.executable, "-m", "tanktool", "import-arena", str(obj), "-o", str(bundle)],
                           check=True, capture_output=True)
        out.append(str(bundle))
    return out


def print_table(rows: list[dict]) -> None:
    names = [n for n, _ in HOOKS]
    print(f"{'arena':<14}{'nodes':>12}{'steps/s':>9}{'x box':>7}{'later':>8}{'x box':>7}{'cpu':>7}{'x box':>7}"
          f"{'peak MB':>9}"
          f"{'1st step s':>11}{'prep s':>8}  "
          + "".join(f"{n + ' s/MB':>18}" for n in names))
    for r in rows:
        if "error" in r:
            print(f"{r['arena']:<14} error: {r['error']}")
            continue
        ph = r["phases"]
        cells = "".join(f"{ph[n]['seconds']:>9.2f}/{ph[n]['added_mb']:<8.0f}" if n in ph else f"{'-':>18}"
                        for n in names)
        print(f"{r['arena']:<14}{r['nodes'] or 0:>12,}{r['steps_per_second']:>9.0f}{r.get('x_box') or 0:>7.2f}"
              f"{r['after_first_steps_per_second'] or 0:>8.0f}{r.get('x_box_later') or 0:>7.2f}"
              f"{r.get('after_first_steps_per_cpu_second') or 0:>7.0f}{r.get('x_box_cpu') or 0:>7.2f}"
              f"{r['peak_mb']:>9.0f}{r['first_step_s'] or 0:>11.2f}{r.get('prepare_s') or 0:>8.2f}  " + cells)
    print("steps/s: the match loop's (tanktool play's figure; the bots' arena tables are made before it, prep s);"
          " later: the steps after the first (cpu: per CPU second of the process); x box: over the box arena's in this run; 1st step s: from loading to"
          " the first step's end (World, prep, first think); MB of a phase: resident size it added at its peak")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--arena", action="append", default=[], help="a terrain bundle (repeatable)")
    ap.add_argument("--make", default="", help="terrain sizes (m) to import into --cache, e.g. 1000,2000")
    ap.add_argument("--cache", type=Path, default=Path("/tmp/tanktool-match-scale"))
    ap.add_argument("--bots", type=int, default=8)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("--repeat", type=int, default=1, help="runs of each match (in turn); the fastest kept")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    if a.child is not None:
        print(json.dumps(child(a.child, a.bots, a.seconds, a.seed)))
        return 0
    arenas = [str(ROOT / "arenas" / "box")] + a.arena
    if a.make:
        arenas += make_terrains([float(s) for s in a.make.split(",") if s], a.cache)
    rows = best_of(arenas, a)
    box, box_later = rows[0].get("steps_per_second"), rows[0].get("after_first_steps_per_second")
    box_cpu = rows[0].get("after_first_steps_per_cpu_second")
    for r in rows:
        if "error" not in r and box:
            r["x_box"] = round(r["steps_per_second"] / box, 3)
        if "error" not in r and box_later and r.get("after_first_steps_per_second"):
            r["x_box_later"] = round(r["after_first_steps_per_second"] / box_later, 3)
        if "error" not in r and box_cpu and r.get("after_first_steps_per_cpu_second"):
            r["x_box_cpu"] = round(r["after_first_steps_per_cpu_second"] / box_cpu, 3)
    if a.json:
        print(json.dumps({"bots": a.bots, "seconds": a.seconds, "seed": a.seed, "rows": rows}))
    else:
        print_table(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
