"""``tanktool tournament``: a round robin of bots (built-in names or FILE.py:Class)
over arenas and vehicles; prints W-L-D per pairing and Elo ratings, writes the JSON
report, a chart and the replay of every match (docs/tournament.md)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from ..errors import TanktoolError
from .main import echo
from .options import progress


def _outputs(json_path: Path | None, chart: Path | None, replays: Path | None,
             no_replays: bool) -> tuple[Path | None, Path | None]:
    """Where the chart and the replays go: given, or beside the JSON report."""
    if json_path is not None:
        chart = chart or json_path.with_suffix(".png")
        replays = replays or json_path.with_name(json_path.stem + "-replays")
    return chart, None if no_replays else replays


def _check_replay_dir(folder: Path, names: list[str]) -> None:
    """Refuse to overwrite a file in the folder that is not a tanktool replay."""
    if folder.exists() and not folder.is_dir():
        raise TanktoolError(f"{folder}: exists and is not a folder (--replays)")
    for name in names:
        p = folder / name
        if p.exists():
            with open(p, "rb") as f:
                if f.read(4) != b"TTRP":
                    raise TanktoolError(f"{p}: exists and is not a tanktool replay; not overwriting it")


@click.command("tournament")
@click.option("--bot", "bots", multiple=True, metavar="NAME|FILE.py:Class",
              help="A player (repeat, at least two): easy, normal, hard, robot, camper, duellist, novice, "
                   "a bot class in a file, or scripted (the old scripted baseline).")
@click.option("--arena", "arenas", multiple=True, metavar="A", help="Arena (repeat; default: box).")
@click.option("--vehicle", "vehicles", multiple=True, metavar="V", help="Vehicle (repeat; default: light).")
@click.option("--matches", type=click.IntRange(1, 10000), default=2, show_default=True,
              help="Matches per pairing, arena and vehicle (sides alternate).")
@click.option("--seconds", type=click.FloatRange(0, 86400, min_open=True), default=60.0, show_default=True,
              help="Simulated seconds per match.")
@click.option("--seed", "first_seed", type=click.IntRange(0, 2 ** 32), default=0, show_default=True,
              help="Match k of a pairing uses seed SEED + k.")
@click.option("--json", "json_path", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="Write the report here (and, unless told otherwise, the chart and replays beside it).")
@click.option("--chart", type=click.Path(path_type=Path, dir_okay=False), default=None,
              help="PNG chart (default: the JSON's name with .png).")
@click.option("--replays", type=click.Path(path_type=Path, file_okay=False), default=None,
              help="Folder for one replay per match (default: <json stem>-replays/ beside the JSON).")
@click.option("--no-replays", is_flag=True, help="Do not record the matches.")
@click.option("--workers", type=click.IntRange(1, 1024), default=None,
              help="Processes (default: the local cores; 1 plays in this process).")
@click.option("--ray", "ray_address", default=None, metavar="ADDRESS|local",
              help="Run on a Ray cluster (local: start one on this machine). Needs tanktool[cluster].")
@click.option("--boot", type=click.IntRange(0, 100000), default=200, show_default=True,
              help="Bootstrap resamples for the Elo intervals.")
def tournament(bots: tuple[str, ...], arenas: tuple[str, ...], vehicles: tuple[str, ...], matches: int,
               seconds: float, first_seed: int, json_path: Path | None, chart: Path | None,
               replays: Path | None, no_replays: bool, workers: int | None, ray_address: str | None,
               boot: int) -> None:
    """Play bots against each other: a round robin of duels.

    \b
    Examples:
      tanktool tournament --bot hard --bot normal --bot examples/bots/sniper.py:Sniper \\
          --arena box --arena hills --matches 4 --json results/t.json
      tanktool tournament --bot mine.py:Mine --bot hard --ray local --workers 2
    """
    from ..formats.bundle import atomic_write_bytes, atomic_write_text
    from ..tournament import TournamentConfig, default_workers, resolve_players, run_tournament, schedule, table

    config = TournamentConfig(tuple(bots), tuple(arenas) or ("box",), tuple(vehicles) or ("light",), matches,
                              seconds, first_seed, boot)
    config.check()
    chart, replays = _outputs(json_path, chart, replays, no_replays)
    players = resolve_players(config.bots)      # a bad bot is one error line before anything runs
    _load_all(config)
    tasks = schedule(config, players)
    if replays is not None:
        _check_replay_dir(replays, [t.replay_name() for t in tasks])
    for out in (json_path, chart):          # where the results go exists before the matches run
        if out is not None:
            out.parent.mkdir(parents=True, exist_ok=True)
    if replays is not None:
        replays.mkdir(parents=True, exist_ok=True)
    written = []

    def keep(name: str, data: bytes) -> None:        # each replay written as its match ends
        atomic_write_bytes(replays / name, data)    # type: ignore[operator]
        written.append(name)

    run = "ray" if ray_address else ("serial" if workers == 1 else "pool")
    n = workers or default_workers()
    if run == "ray":            # connected (or refused) before the progress bar
        from ..tournament.runners import ray_connect

        ray_connect(ray_address or "local", n)
    with progress(length=len(tasks), label=f"{len(tasks)} matches ({run}, {n if run != 'serial' else 1} "
                  f"worker{'s' if n > 1 and run != 'serial' else ''})") as bar:
        result = run_tournament(config, run=run, workers=n, ray_address=ray_address or "local",
                                record=replays is not None, on_match=lambda r: bar.update(1),
                                on_replay=keep if replays is not None else None)
    echo(table(result.report))
    if replays is not None:
        echo(f"wrote {len(written)} replays to {replays}/ (tanktool play --headless --replay FILE)")
    if json_path is not None:
        atomic_write_text(json_path, json.dumps(result.report, indent=1) + "\n")
        echo(f"wrote {json_path}")
    if chart is not None:
        from ..tournament.chart import chart_png

        atomic_write_bytes(chart, chart_png(result.report))
        echo(f"wrote {chart}")


def _load_all(config) -> None:
    """Every arena and vehicle loaded once here, so that a bad one is one error line
    before any match runs (and a vehicle too big for an arena is said up front)."""
    from ..sim.match import choose_vehicle, load_match_arena

    for a in config.arenas:
        info = load_match_arena(a)
        for v in config.vehicles:
            choose_vehicle(info, v)
