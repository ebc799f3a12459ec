"""A tournament's report: the matches (sorted by index), W-L-D per pairing (per
arena and vehicle, and over all of them), Elo ratings with bootstrap intervals; the
table the command prints; everything that depends on the machine under ``timing``.

The report without ``timing`` is the same whichever way the matches ran."""

from __future__ import annotations

from typing import Any

from .elo import elo_table
from .schedule import MatchTask, Player, TournamentConfig

FORMAT = "tanktool-tournament"
VERSION = 1


def _wld(rows: list[dict]) -> dict[str, int]:
    return {"wins": sum(r["score"] == 1.0 for r in rows), "losses": sum(r["score"] == 0.0 for r in rows),
            "draws": sum(r["score"] == 0.5 for r in rows)}


def make_report(config: TournamentConfig, players: list[Player], tasks: list[MatchTask],
                results: list[dict[str, Any]]) -> dict[str, Any]:
    """The report of finished matches (``results`` in any order)."""
    results = sorted(results, key=lambda r: r["index"])
    names = [p.name for p in players]
    cells: dict[tuple, list[dict]] = {}
    pairs: dict[tuple[int, int], list[dict]] = {}
    games = []
    cell_ids: dict[tuple, int] = {}
    for task, r in zip(tasks, results):
        cells.setdefault(task.cell, []).append(r)
        pairs.setdefault((task.a, task.b), []).append(r)
        games.append((task.a, task.b, r["score"], cell_ids.setdefault(task.cell, len(cell_ids))))
    pairings = []
    for (a, b, arena, vehicle), rows in cells.items():
        pairings.append({"a": names[a], "b": names[b], "arena": rows[0]["arena"], "vehicle": rows[0]["vehicle"],
                         **_wld(rows), "kills": [sum(r["kills"][0] for r in rows), sum(r["kills"][1] for r in rows)]})
    totals = [{"a": names[a], "b": names[b], **_wld(rows)} for (a, b), rows in pairs.items()]
    matches = [{k: v for k, v in r.items() if k not in ("timing", "replay")} for r in results]
    errors = [0] * len(players)
    for task, r in zip(tasks, results):
        for who, n in zip((task.a, task.b), r.get("bot_errors", (0, 0))):
            errors[who] += n
    report = {
        "format": FORMAT, "version": VERSION,
        "bots": [p.public() for p in players],
        "arenas": list(dict.fromkeys(r["arena"] for r in results)),
        "vehicles": list(dict.fromkeys(r["vehicle"] for r in results)),
        "matches_per_pairing": config.matches, "seconds": config.seconds, "first_seed": config.first_seed,
        "rule": "a match is won with more kills; equal kills is a draw",
        "elo": elo_table(names, games, boot=config.boot),
        "elo_interval": 0.95, "bootstrap": config.boot,
        "totals": totals, "pairings": pairings, "matches": matches,
    }
    if any(errors):
        report["bot_errors"] = {n: e for n, e in zip(names, errors) if e}
    return report


def add_timing(report: dict[str, Any], results: list[dict[str, Any]], runner: str, workers: int,
               wall: float) -> None:
    """What depends on the machine: how it ran, the wall clock, the bots' time per call."""
    calls: dict[str, dict[str, float]] = {}
    for r in results:
        for name, st in zip((r["a"], r["b"]), r["timing"]["bots"]):
            if st:
                c = calls.setdefault(name, {"calls": 0, "over_budget": 0, "total_ms": 0.0, "max_ms": 0.0})
                c["calls"] += st["calls"]
                c["over_budget"] += st["over_budget"]
                c["total_ms"] += st["mean_ms"] * st["calls"]
                c["max_ms"] = max(c["max_ms"], st["max_ms"])
    bots = {n: {"calls": c["calls"], "over_budget": c["over_budget"],
                "mean_ms": round(c["total_ms"] / max(c["calls"], 1), 4), "max_ms": c["max_ms"]}
            for n, c in calls.items()}
    match_s = sum(r["timing"]["wall_clock_s"] for r in results)
    report["timing"] = {"runner": runner, "workers": workers, "wall_clock_s": round(wall, 3),
                        "matches_per_second": round(len(results) / wall, 3) if wall > 0 else None,
                        "match_s_total": round(match_s, 3), "bots": bots}


def table(report: dict[str, Any]) -> str:
    """W-L-D of the first bot of each pair, per arena/vehicle and over all, then the
    Elo ratings, best first."""
    cols = [(p["arena"], p["vehicle"]) for p in report["pairings"]]
    cols = list(dict.fromkeys(cols))
    heads = [f"{a}/{v}" for a, v in cols] + ["all"]
    width = max([12] + [len(h) + 2 for h in heads])
    pw = max([18] + [len(t["a"]) + len(t["b"]) + 6 for t in report["totals"]])
    lines = [f"W-L-D of the first bot of each pair, {report['matches_per_pairing']} matches of "
             f"{report['seconds']:g} s per pairing and arena/vehicle",
             f"{'pair':<{pw}}" + "".join(f"{h:>{width}}" for h in heads)]
    lines.append("-" * len(lines[-1]))
    for t in report["totals"]:
        row = f"{t['a'] + ' vs ' + t['b']:<{pw}}"
        for arena, vehicle in cols:
            c = next(p for p in report["pairings"] if (p["a"], p["b"], p["arena"], p["vehicle"])
                     == (t["a"], t["b"], arena, vehicle))
            row += f"{c['wins']}-{c['losses']}-{c['draws']}".rjust(width)
        lines.append(row + f"{t['wins']}-{t['losses']}-{t['draws']}".rjust(width))
    lines += ["", f"{'bot':<{pw}}{'Elo':>8}  95 % interval"]
    for r in sorted(report["elo"], key=lambda r: -r["elo"]):
        lines.append(f"{r['bot']:<{pw}}{r['elo']:>8.0f}  [{r['lo']:.0f}, {r['hi']:.0f}]")
    if report.get("bot_errors"):
        lines.append("bot failures (idle for that step): " +
                     ", ".join(f"{n} {e}" for n, e in report["bot_errors"].items()))
    return "\n".join(lines)
