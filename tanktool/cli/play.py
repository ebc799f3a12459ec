"""``tanktool play``: a match.

``--headless`` runs the bots (computer agents at ``--difficulty``, or with
``--bot-driver scripted`` the old scripted bots) without window or sound as fast as
the machine allows and can write a JSON report; with ``--frames``/``--screenshot`` it renders one picture
of the 3D or top view instead (``tanktool.game.headless``).  Without ``--headless`` the
game window opens (``tanktool.game.app``); when there is no display to open it on, the
command says so and does the best thing that exists: a short headless match on the
default arena and a scoreboard (and, with ``--picture``, a top view of the final
state: nothing is written into the working folder unless asked for).

``--seconds`` is the length of a match everywhere: headless, and in the window, where
each local match ends after that much simulated time and the menu comes back.  A
replay lasts as long as its recording, and a network match in the window until you
quit: there ``--seconds`` is refused/ignored with a word, never silently.

``--time-limit`` and ``--score-limit`` are the match's end by its rules
(``sim.rules``): it is over when the time is up or a tank has that many kills, the
world stops and the scoreboard says who won.  Headless, ``--seconds`` (default: the
time limit, else 60) still caps the run.  A replay keeps the limits it was recorded
with; network matches have none yet (refused).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ..errors import ArenaError, TanktoolError
from .main import echo
from .net_play import network_options
from .options import progress

if TYPE_CHECKING:
    from ..game.config import MatchConfig


def _arena_ref(arena: str | None) -> str:
    from ..sim.match import default_arena

    ref = arena or default_arena()
    if ref is None:
        raise ArenaError("no arena given and none bundled under arenas/ (use --arena PATH)")
    return ref


def _fresh_arena(arena: str | None) -> None:
    """No silent fallback: the arena's derived files rebuilt when missing or stale (one
    line on stderr says so), or an ArenaError naming the command that fixes them."""
    from ..freshness import ensure_fresh
    from ..sim.match import arena_dir, default_arena

    ref = arena or default_arena()
    if ref is None:
        return
    ensure_fresh(arena_dir(ref), say=lambda line: click.echo(line, err=True))


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise click.BadParameter(f"expected WIDTHxHEIGHT like 1280x720, got {text!r}", param_hint="--size") from None
    if not (64 <= w <= 8192 and 64 <= h <= 8192):
        raise click.BadParameter(f"{w}x{h}: each side must be 64..8192 pixels", param_hint="--size")
    return w, h


@click.command("play")
@click.option("--headless", is_flag=True, help="No window or sound: run the bots as fast as possible.")
@click.option("--arena", "arena", default=None, metavar="A",
              help="Arena bundle: a folder, or the name of a bundled one (box, fort, hills, maze, paper2002).")
@click.option("--vehicle", "vehicle", default=None, metavar="V",
              help="Vehicle bundle: a folder, or the name of a bundled one (light, heavy).")
@click.option("--bots", type=click.IntRange(1, 64), default=None, help="Number of tanks (default 8 headless, 4 otherwise).")
@click.option("--seconds", type=click.FloatRange(0, 86400, min_open=True), default=None,
              help="Length of a match in simulated seconds: headless (default 60), in the window (each "
                   "match ends after it; default: when you quit), without a display (default 20).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed: same seed, same match.")
@click.option("--difficulty", type=click.Choice(["easy", "normal", "hard"]), default=None,
              help="Computer opponents' skill: reaction time, aim noise, vision range (default: normal headless; "
                   "in the window the menu's last choice, easy on a first start).")
@click.option("--bot", "bot_specs", multiple=True, metavar="NAME|FILE.py:Class",
              help="A bot driving a computer tank (repeat for more): easy, normal, hard, robot, camper, duellist, "
                   "novice, or a bot class in a file (docs/bots.md); --bots fills the other tanks with "
                   "--difficulty agents.")
@click.option("--bot-driver", "bot_driver", type=click.Choice(["agent", "scripted"]), default="agent",
              show_default=True, help="Who drives the bots: the computer agent, or the old scripted bot (the baseline).")
@click.option("--integrator", type=click.Choice(["semi-implicit", "euler"]), default="semi-implicit",
              show_default=True, help="Semi-implicit Euler, or the 2002 paper's explicit Euler.")
@click.option("--report", "report_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the match report (JSON) here.")
@click.option("--picture", "picture", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Save a top view of the final state (PNG): headless, or without a display.")
@click.option("--view", type=click.Choice(["3d", "top"]), default="3d", show_default=True,
              help="3D view (OpenGL) or the 2D top-down view: the window's first view, or what --screenshot renders.")
@click.option("--frames", type=click.IntRange(0, 1_000_000), default=None,
              help="With --headless: render after this many frames (1/60 s each) instead of running a match.")
@click.option("--screenshot", "screenshot", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="With --headless: write the view after --frames frames (default 120) to this PNG.")
@click.option("--size", default="1280x720", show_default=True, metavar="WxH", help="Window or screenshot size.")
@click.option("--fullscreen", is_flag=True, help="Open the window full screen.")
@click.option("--record", "record_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Record the match (setup, seed, every tank's commands, yours too) to this replay file "
                   "(.ttr).  In the window the file is written when a match ends and holds the last one.")
@click.option("--replay", "replay_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Play a recorded match back from this file: the same final state, bit for bit.  In the "
                   "window unless --headless, --report or --picture.")
@click.option("--quality", type=click.Choice(["low", "medium", "high"]), default=None,
              help="3D graphics preset for this run (default: the settings page's, medium): low for slow "
                   "software OpenGL, high for shadows on everything and Phong lighting.")
@click.option("--time-limit", "time_limit", type=click.FloatRange(0, 86400, min_open=True), default=None,
              metavar="S", help="The match ends after S simulated seconds (its rules: the scoreboard says who won).")
@click.option("--score-limit", "score_limit", type=click.IntRange(1, 1_000_000), default=None, metavar="K",
              help="The match ends when a tank has K kills.")
@click.option("--watch", "watch", type=click.Path(dir_okay=False, path_type=Path), default=None, metavar="MODEL",
              help="The authoring loop: import MODEL (.obj, .glb, .3ds, ...) into a scratch bundle, play it in "
                   "the window, and reload the arena there whenever the file changes on disk.")
@network_options
def play(headless: bool, arena: str | None, vehicle: str | None, bots: int | None, seconds: float | None,
         seed: int, integrator: str, report_path: Path | None, picture: Path | None, view: str,
         frames: int | None, screenshot: Path | None, size: str, fullscreen: bool,
         host: str | None = None, join: str | None = None, player_name: str | None = None,
         password: str | None = None, difficulty: str | None = None, bot_driver: str = "agent",
         record_path: Path | None = None, replay_path: Path | None = None,
         time_limit: float | None = None, score_limit: int | None = None, quality: str | None = None,
         bot_specs: tuple[str, ...] = (), watch: Path | None = None) -> None:
    """Play a match: bots on an arena.

    \b
    Examples:
      tanktool play --headless --arena box --bots 8 --seconds 60 --seed 1 --report match.json
      tanktool play --headless --arena arenas/maze --vehicle heavy --seconds 600
      tanktool play --headless --frames 120 --screenshot shot.png --view 3d
      tanktool play --arena maze --view top
      tanktool play --headless --arena box --seconds 30 --seed 4 --record match.ttr
      tanktool play --replay match.ttr --report again.json --picture end.png
      tanktool play --arena maze --record mine.ttr      (the window; the file holds the last match)
      tanktool play --replay mine.ttr                   (watch it in the window)
      tanktool play --headless --bot examples/bots/sniper.py:Sniper --bot hard --bots 4
    """
    opts = _Options(headless, arena, vehicle, bots, seconds, seed, integrator, report_path, picture, view, frames,
                    screenshot, _size(size), fullscreen, difficulty, bot_driver, record_path, replay_path,
                    time_limit, score_limit, quality, tuple(bot_specs))
    if bot_specs:
        _check_bots(opts, host is not None or join is not None)
    if replay_path is None:   # a replay plays what it recorded (its fingerprints say if that changed)
        _fresh_arena(opts.arena)
    if watch is not None:
        _play_watch(opts, watch, host is not None or join is not None)
        return
    if host is not None or join is not None:
        _play_network(opts, host, join, player_name, password)
        return
    if record_path is not None or replay_path is not None:
        if _replay_setup(opts):
            return
    if opts.headless and (frames is not None or screenshot is not None):
        _screenshot(opts)
        return
    if not opts.headless:
        if _play_window(opts, window_config(opts)):
            return
        opts.bots = 4 if opts.bots is None else opts.bots
        opts.seconds = 20.0 if opts.seconds is None else opts.seconds
    _play_headless(opts)


@dataclass
class _Options:
    """``play``'s options as given (the window's part becomes a MatchConfig)."""

    headless: bool
    arena: str | None
    vehicle: str | None
    bots: int | None
    seconds: float | None
    seed: int
    integrator: str
    report_path: Path | None
    picture: Path | None
    view: str
    frames: int | None
    screenshot: Path | None
    size: tuple[int, int]
    fullscreen: bool
    difficulty: str | None
    bot_driver: str
    record_path: Path | None
    replay_path: Path | None
    time_limit: float | None
    score_limit: int | None
    quality: str | None
    bot_specs: tuple[str, ...] = ()

    @property
    def level(self) -> str:
        """The opponents' difficulty in a match without the window's menu."""
        return self.difficulty or "normal"

    @property
    def limits(self) -> bool:
        return self.time_limit is not None or self.score_limit is not None


def window_config(o: _Options, replay: Any = None) -> "MatchConfig":
    """The one match configuration the game window gets from ``play``'s options
    (``--bots`` counts every tank, yours too: the window gets that many less one)."""
    from ..game.config import MatchConfig, Opponents, Recording, ViewConfig
    from ..sim.match import match_rules

    rules = match_rules(None, o.time_limit, o.score_limit) if o.limits else None
    count = max(3 if o.bots is None else max(o.bots - 1, 0), len(o.bot_specs))
    return MatchConfig(arena=o.arena, vehicle=o.vehicle,
                       opponents=Opponents(count, o.difficulty, o.bot_driver, tuple(o.bot_specs)),
                       seed=o.seed, rules=rules, seconds=o.seconds,
                       view=ViewConfig(o.view, o.size, o.fullscreen, o.quality),
                       recording=Recording(record=o.record_path, replay=replay,
                                           replay_name=str(o.replay_path or "")))


def _check_bots(o: _Options, network: bool) -> None:
    """--bot: where it applies, and every bot loaded once (a bad one is one error line)."""
    from ..sim.bots.lineup import lineup

    if network and not o.headless:
        raise click.UsageError("--bot in a network match: host it with --headless (the bots run on the host)")
    if o.frames is not None or o.screenshot is not None:
        raise click.UsageError("--bot plays a match; --frames/--screenshot render a picture (use --picture)")
    if o.replay_path is not None:
        click.echo("warning: --bot ignored: a replay plays the recorded commands", err=True)
        o.bot_specs = ()
        return
    if o.bots is not None and o.bots < len(o.bot_specs) + (0 if o.headless else 1):
        raise click.UsageError(f"--bots {o.bots} leaves no tank for {len(o.bot_specs)} --bot "
                               f"(it counts every tank{'' if o.headless else ', yours too'})")
    lineup(o.bot_specs)


def _play_watch(o: _Options, model: Path, network: bool) -> None:
    """``--watch MODEL``: import it into a scratch bundle and play it in the window,
    reloading it there when the file changes (game/watch.py)."""
    from ..game.app import display_problem
    from ..game.watch import ModelWatch

    if o.arena is not None or o.headless or network or o.replay_path or o.record_path or o.frames is not None \
            or o.screenshot is not None:
        raise click.UsageError("--watch plays its model in the window: it goes without --arena, --headless, "
                               "--host/--join, --record/--replay and --frames/--screenshot")
    if not model.is_file():
        raise TanktoolError(f"{model}: no such model file to watch")
    problem = display_problem()
    if problem is not None:
        raise TanktoolError(f"--watch needs the game window, and there is no display here ({problem})")
    watcher = ModelWatch(model)
    try:
        o.arena = str(watcher.import_now())
        echo(f"watching {model}: imported into {o.arena}; save the file to reload the arena in the window")
        config = window_config(o)
        config.watch = watcher
        _play_window(o, config)
    finally:
        watcher.close()


def _play_network(o: _Options, host: str | None, join: str | None, player_name: str | None,
                  password: str | None) -> None:
    from .net_play import resolve_password, run_network, run_network_window

    if o.limits:
        raise click.UsageError("--time-limit/--score-limit: network matches have no match end yet")
    if o.record_path is not None or o.replay_path is not None:
        raise click.UsageError("network matches are not recorded: --record/--replay go without --host/--join")
    password = resolve_password(password)      # '-': typed at a prompt, once for both paths below
    if not o.headless and o.seconds is not None and _window_possible():
        click.echo("warning: --seconds is ignored in a network match in the window (it lasts until you "
                   "quit); use --headless for a timed network match", err=True)
    if not o.headless and run_network_window(host, join, player_name, password, o.arena, o.vehicle, o.bots,
                                             o.seed, o.view, o.size, o.fullscreen, echo):
        return
    run_network(host, join, player_name, password, o.arena, o.vehicle, o.seconds, o.seed, o.report_path, echo,
                bot_specs=o.bot_specs)


def _replay_setup(o: _Options) -> bool:
    """--record/--replay: check them, render a replay's frame or show it in the window
    (True: done), else set the options up for the headless match that records or
    plays it back."""
    if o.record_path is not None and o.replay_path is not None:
        raise click.UsageError("--record and --replay cannot be used together")
    if o.replay_path is not None and (o.frames is not None or o.screenshot is not None):
        _replay_picture(o)
        return True
    if o.frames is not None or o.screenshot is not None:
        raise click.UsageError("--record records a match, --frames/--screenshot render a picture: "
                               "use --picture for the final view")
    _check_folders(o.record_path, o.report_path, o.picture)
    if o.replay_path is None:
        return False
    if o.seconds is not None:
        click.echo(f"warning: --seconds {o.seconds:g} ignored: a replay lasts as long as its recording", err=True)
        o.seconds = None
    if o.limits:
        click.echo("warning: --time-limit/--score-limit ignored: a replay keeps the rules it was recorded with",
                   err=True)
        o.time_limit = o.score_limit = None
    if not o.headless and o.report_path is None and o.picture is None:
        # the recording in the game window; no display: the headless playback and its check
        from ..sim.replay import read_replay

        if _play_window(o, window_config(o, replay=read_replay(o.replay_path)), what="show the replay",
                        instead="playing it back headless instead."):
            return True
    o.headless = True
    return False


def _replay_picture(o: _Options) -> None:
    """One frame of the recorded match, rendered like --screenshot (default: the last)."""
    from ..game.headless import FRAME
    from ..game.headless import screenshot as take_screenshot
    from ..game.replay_session import replay_frames, replay_session
    from ..sim.replay import read_replay

    if o.screenshot is None:
        raise click.UsageError("--frames needs --screenshot FILE.png")
    tape = read_replay(o.replay_path)
    total = replay_frames(tape, FRAME)
    n = total if o.frames is None else o.frames
    if n > total:
        raise TanktoolError(f"{o.replay_path}: the recording has {total} frames, --frames asked for {n}")
    shot = take_screenshot(o.screenshot, view=o.view, frames=n, size=o.size,
                           session=replay_session(tape, o.arena, o.vehicle))
    echo(f"{shot['view']} view of {o.replay_path} at frame {shot['frames']} of {total}: {shot['path']}")


def _screenshot(o: _Options) -> None:
    from ..game.headless import screenshot as take_screenshot

    if o.screenshot is None:
        raise click.UsageError("--frames needs --screenshot FILE.png")
    shot = take_screenshot(o.screenshot, view=o.view, frames=120 if o.frames is None else o.frames, arena=o.arena,
                           vehicle=o.vehicle, bots=8 if o.bots is None else o.bots, seed=o.seed, size=o.size,
                           difficulty=o.level, bot=o.bot_driver, quality=o.quality or "medium")
    echo(f"{shot['view']} view after {shot['frames']} frames: {shot['path']}")


def _play_window(o: _Options, config: "MatchConfig", what: str = "open the game window",
                 instead: str = "running a short headless match instead (tanktool play --headless for options; "
                                "--picture F.png saves a top view).") -> bool:
    """The game window with ``config``; False (and a line) when there is no display."""
    from ..game.app import NoDisplay, run_window

    try:
        saved = run_window(config)
    except NoDisplay as e:
        echo(f"no display to {what} ({e}); {instead}")
        return False
    for line in saved:
        echo(line)
    if o.record_path is not None and not saved:
        echo(f"replay: nothing recorded (no match was played), {o.record_path} not written")
    return True


def _check_folders(*outs: Path | None) -> None:
    for out in outs:
        if out is not None and not out.parent.exists():
            raise TanktoolError(f"{out}: folder {out.parent} does not exist")


def _play_headless(o: _Options) -> None:
    """A match without a window, as fast as the machine allows: scoreboard, report,
    picture, recording, or a replay played back and checked."""
    from ..sim.match import (choose_vehicle, default_vehicle, format_report, load_match_arena, load_tank_spec,
                             run_match, scoreboard)

    bots = max(8, len(o.bot_specs)) if o.bots is None else o.bots
    seconds = o.seconds if o.seconds is not None else o.time_limit if o.time_limit is not None else 60.0
    wrap = None
    if o.bot_specs:         # --bot: the first tanks are those bots, the others --difficulty agents
        from ..sim.bots.lineup import lineup, seat

        listed = lineup(o.bot_specs)

        def wrap(world: Any, drivers: list) -> list:
            return seat(world, listed, 0, drivers)
    arena, vehicle, replay = o.arena, o.vehicle, None
    if o.replay_path is not None:
        from ..sim.replay import read_replay

        replay = read_replay(o.replay_path)
        # the recording says what was played; --arena/--vehicle may point at moved bundles
        arena = arena or replay.header.get("arena_ref")
        vehicle = vehicle or replay.header.get("vehicle_ref")
        bots, seconds = int(replay.header["bots"]), float(replay.header["seconds"])
    _check_folders(o.report_path, o.picture, o.record_path)
    info = load_match_arena(_arena_ref(arena))
    # a replay plays what it recorded; a new match only with a vehicle the arena is built for
    vref = (vehicle or default_vehicle()) if replay is not None else choose_vehicle(info, vehicle, echo)
    spec = load_tank_spec(vref)
    if vref is None:
        echo("no vehicle bundled yet: using the built-in box tank")
    steps = int(round(seconds * 120))
    with progress(length=steps, label=f"{info.name}: {bots} bots, {seconds:g} s") as bar:
        if replay is not None:
            from ..sim.replay import play_replay

            playback = play_replay(replay, info, spec, on_progress=bar.update)
            result = playback.result
        elif o.record_path is not None:
            from ..sim.replay import record_match

            result, tape = record_match(info, spec, bots=bots, seconds=seconds, seed=o.seed,
                                        arena_ref=_stored_ref(_arena_ref(arena)), vehicle_ref=_stored_ref(vref),
                                        on_progress=bar.update, integrator=o.integrator, bot=o.bot_driver,
                                        difficulty=o.level, wrap_drivers=wrap,
                                        extra={"bot_specs": list(o.bot_specs)} if o.bot_specs else None,
                                        **_limit_options(o.time_limit, o.score_limit))
        else:
            result = run_match(info, spec, bots=bots, seconds=seconds, seed=o.seed, integrator=o.integrator,
                               on_progress=bar.update, bot=o.bot_driver, difficulty=o.level,
                               time_limit=o.time_limit, score_limit=o.score_limit, wrap_drivers=wrap)
    report = result.report
    echo(scoreboard(report))
    timing = report["timing"]
    echo(f"{report['steps']} steps in {timing['wall_clock_s']:.2f} s: "
         f"{timing['steps_per_second']:.0f} steps/s, {timing['realtime_factor']:.1f}x real time"
         + (f" (bots prepared in {timing['prepare_s']:.2f} s before)" if timing.get("prepare_s", 0) >= 0.05 else ""))
    if o.report_path is not None:
        from ..formats.bundle import atomic_write_text

        atomic_write_text(o.report_path, format_report(report))
        echo(f"report: {o.report_path}")
    if o.picture is not None:
        from ..plots.match import save_match_picture

        save_match_picture(result, o.picture)
        echo(f"picture: {o.picture}")
    if o.record_path is not None:
        from ..sim.replay import write_replay

        nbytes = write_replay(o.record_path, tape)
        echo(f"replay: {o.record_path} ({nbytes} bytes, {len(tape)} command changes)")
    if replay is not None:
        if not playback.matches:
            raise click.ClickException(f"replay diverged from the recording: final state sha256 "
                                       f"{playback.digest[:16]}..., recorded {replay.header['final_state'][:16]}...")
        echo(f"replay: final state matches the recording bit for bit (sha256 {playback.digest[:16]}...)")


def _limit_options(time_limit: float | None, score_limit: int | None) -> dict:
    """The limits as run_match options (only those given: a recording stores them)."""
    return {k: v for k, v in (("time_limit", time_limit), ("score_limit", score_limit)) if v is not None}


def _window_possible() -> bool:
    from ..game.app import display_problem

    return display_problem() is None


def _stored_ref(ref: str | None) -> str | None:
    """A bundle reference as a replay stores it: an existing path made absolute (so
    the replay plays from any folder), a bundled name as it is."""
    if ref is None:
        return None
    p = Path(ref)
    return str(p.resolve()) if p.exists() else ref
