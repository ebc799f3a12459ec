"""``tanktool play --host [ADDR:]PORT`` / ``--join ADDR:PORT``: network play.

The options are defined here once and stacked on ``play`` (``network_options``); the
command hands over to :func:`run_network` when either is given.  ``--bots N`` with
``--host`` adds N computer opponents that the host runs (and a new host adopts).  Without
``--headless`` the match opens in the game window (:func:`run_network_window`), your
tank driven by your keys, until you quit; the window's start menu offers the same
(network: off/host/join, address).  With ``--headless`` (or no display) the local tank
is driven by the scripted bot, for ``--seconds`` of real time, and ``--report`` writes
the match report with ``peers``, ``host_changes`` and ``network`` counters.

The session password can stay off the command line (where ``ps`` shows it to every
local user): ``TANKTOOL_PASSWORD`` in the environment, or ``--password -`` to type it at
a prompt that does not echo (read as one line from standard input when that is not a
terminal).
"""

from __future__ import annotations

import json
import signal
import sys
from pathlib import Path
from typing import Any, Callable

import click

from ..errors import NetError, TanktoolError

DEFAULT_NET_SECONDS = 60.0
#: the environment variable ``--password`` is read from when not given
PASSWORD_ENV = "TANKTOOL_PASSWORD"


def network_options(f: Callable) -> Callable:
    """``--host``, ``--join``, ``--name``, ``--password`` for ``tanktool play``."""
    f = click.option("--password", default=None, metavar="TEXT", envvar=PASSWORD_ENV, show_envvar=True,
                     help="Session password (checked with an HMAC challenge, never sent; every datagram is "
                          "authenticated with it).  '-' asks for it at a prompt that does not echo; without "
                          f"the option, ${PASSWORD_ENV} is used.  On the command line other local users can "
                          "see it (ps).")(f)
    f = click.option("--name", "player_name", default=None, metavar="NAME",
                     help="Your player name in a network session (1-24 characters).")(f)
    f = click.option("--join", "join", default=None, metavar="ADDR:PORT",
                     help="Join the network session whose host (or any member) is at ADDR:PORT.")(f)
    f = click.option("--host", "host", default=None, metavar="[ADDR:]PORT",
                     help="Host a network session, listening on ADDR:PORT (ADDR defaults to 127.0.0.1).")(f)
    return f


def resolve_password(password: str | None) -> str | None:
    """The session password: as given, or (``-``) typed at a prompt without echo, or read
    as one line from standard input when that is not a terminal.  Empty means none."""
    if password != "-":
        return password or None
    try:
        if sys.stdin is not None and sys.stdin.isatty():
            text = click.prompt("session password", hide_input=True, err=True, default="", show_default=False)
        else:
            text = sys.stdin.readline().rstrip("\r\n") if sys.stdin is not None else ""
    except (click.Abort, EOFError, KeyboardInterrupt):
        raise click.UsageError("--password -: no password given at the prompt") from None
    if not text:
        raise click.UsageError("--password -: no password given (an empty line)")
    return text


def run_network_window(host: str | None, join: str | None, player_name: str | None, password: str | None,
                       arena: str | None, vehicle: str | None, bots: int | None, seed: int, view: str,
                       size: tuple[int, int], fullscreen: bool, echo: Callable[[str], None]) -> bool:
    """The network match in the game window, your tank driven by your keys (``bots``:
    computer opponents the host runs, as with --headless).  Returns False when there is
    no display (the caller then plays it headless)."""
    from ..game.app import NoDisplay, run_window
    from ..game.config import MatchConfig, NetworkConfig, Opponents, ViewConfig

    bots = bots or 0
    _check_roles(host, join, bots)
    network = ("host", host) if host is not None else ("join", join)
    try:
        lines = run_window(MatchConfig(arena=arena, vehicle=vehicle, opponents=Opponents(count=bots), seed=seed,
                                       view=ViewConfig(view, size, fullscreen),
                                       network=NetworkConfig(*network, player_name, password)))  # type: ignore[arg-type]
    except NoDisplay as e:
        echo(f"no display to open the game window ({e}); the network match runs headless, "
             "the scripted bot driving your tank.")
        return False
    for line in lines:
        echo(line)
    return True


def run_network(host: str | None, join: str | None, player_name: str | None, password: str | None,
                arena: str | None, vehicle: str | None, seconds: float | None, seed: int,
                report_path: Path | None, echo: Callable[[str], None], bots: int | None = None,
                bot_specs: tuple[str, ...] = ()) -> dict[str, Any]:
    """Host or join a session, play it, print a summary, write the report.  ``bots``
    (default: ``play``'s own ``--bots``) computer opponents run on the host, the first
    of them driven by ``bot_specs`` (``play --bot``)."""
    from ..net.names import name_problem
    from ..net.protocol import name_bytes
    from ..net.session import NetMatch
    from ..sim.match import default_arena, load_match_arena, load_tank_spec

    if bots is None:
        # --bots belongs to `play`; read it from there rather than widen play's call
        ctx = click.get_current_context(silent=True)
        bots = ctx.params.get("bots") if ctx is not None else None
    bots = max(bots or 0, len(bot_specs))
    _check_roles(host, join, bots)
    if report_path is not None and not report_path.parent.exists():
        raise TanktoolError(f"{report_path}: folder {report_path.parent} does not exist")
    name = player_name or ("host" if host is not None else "player")
    try:
        name_bytes(name)
    except ValueError as e:
        raise NetError(str(e)) from None
    problem = name_problem(name, [])
    if problem is not None:
        raise NetError(problem)
    ref = arena or default_arena()
    if ref is None:
        raise TanktoolError("no arena given and none bundled under arenas/ (use --arena PATH)")
    info = load_match_arena(ref)
    from ..sim.match import choose_vehicle

    spec = load_tank_spec(choose_vehicle(info, vehicle, echo))   # one the arena is built for
    seconds = DEFAULT_NET_SECONDS if seconds is None else seconds
    from ..net.digest import match_digest, match_label

    # peers on another arena or vehicle are refused at the join (the digests differ)
    same = {"digest": match_digest(info, spec), "label": match_label(info, spec)}
    peer = _open_peer(host, join, name, password, same, echo)
    match = None

    def stop(signum: int, frame: Any) -> None:
        # Ctrl-C or SIGTERM ends the match cleanly: EXIT to everyone, and the report.
        # The handler stays until the report is written, so a second Ctrl-C while the
        # peer says goodbye (up to 0.5 s a link) cannot lose the report
        if match is not None:
            match.stop = True

    def restart_stats(signum: int, frame: Any) -> None:
        # benchmarks measure a window: SIGUSR1 restarts the traffic counters
        if match is not None:
            match.restart_stats = True

    old = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    if hasattr(signal, "SIGUSR1"):
        old[signal.SIGUSR1] = signal.signal(signal.SIGUSR1, restart_stats)
    try:
        try:
            match = NetMatch(peer, info, spec, seed=seed, log=echo, bots=bots, bot_specs=tuple(bot_specs))
            report = match.run(seconds)
        finally:
            peer.close()
        _summary(report, report_path, echo)
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
    return report


def _check_roles(host: str | None, join: str | None, bots: int) -> None:
    """A usage error for --host with --join, bots on a joining peer, or too many bots."""
    if host is not None and join is not None:
        raise click.UsageError("--host and --join exclude each other")
    if bots and join is not None:
        raise click.UsageError("computer opponents run on the host: --bots goes with --host")
    if bots > 7:
        raise click.UsageError(f"--bots {bots}: a session holds 8 tanks, the host's own included (at most 7 bots)")


def _open_peer(host: str | None, join: str | None, name: str, password: str | None, same: dict[str, Any],
               echo: Callable[[str], None]) -> Any:
    """Host a session at ``host`` or join the one at ``join``, and say where we are."""
    from ..net.peer import Peer, parse_address

    if host is not None:
        peer = Peer.host(parse_address(host), name, password, **same)
        ip, port = peer.tcp_address
        echo(f"hosting on {ip}:{port} as player 1 ({name})")
        return peer
    assert join is not None
    peer = Peer.join(parse_address(join, need_host=True), name, password, **same)
    h = peer.table[peer.host_number]
    me_ip, me_port = peer.tcp_address
    echo(f"joined {h.ip}:{h.tcp_port} as player {peer.number} ({name}), listening on {me_ip}:{me_port} "
         f"(udp {peer.udp_address[1]}); host is player {peer.host_number}")
    return peer


def _summary(report: dict[str, Any], report_path: Path | None, echo: Callable[[str], None]) -> None:
    """Print the match summary and write the report (names from the network made visible)."""
    from ..formats.bundle import atomic_write_text
    from ..net.names import visible

    net = report["network"]
    lat = report["latency_ms"]
    echo(f"{report['seconds']:.1f} s as player {report['me']}; host at the end: player {report['host']}; "
         f"{len(report['peers'])} players")
    for p in report["peers"]:
        echo(f"  p{p['number']} {visible(p['name']):<12} kills {p['kills']:>2} deaths {p['deaths']:>2} "
             f"position ({p['position'][0]:.1f}, {p['position'][1]:.1f})")
    echo(f"network: sent {net['sent']}, received {net['received']}, dropped {net['dropped']}; "
         f"state latency p50 {lat['p50']} ms, p99 {lat['p99']} ms")
    if report_path is not None:
        atomic_write_text(report_path, json.dumps(report, indent=1) + "\n")
        echo(f"report: {report_path}")
