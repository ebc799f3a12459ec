"""One match configuration: what the game window is asked to play.

The CLI (``tanktool play``) or the start menu builds a :class:`MatchConfig` once and
hands it to :class:`~tanktool.game.app.App`; nothing downstream takes the choices as
loose arguments.  Example::

    from tanktool.game.config import MatchConfig, Opponents, ViewConfig
    cfg = MatchConfig(arena="hills", opponents=Opponents(count=2, difficulty="easy"),
                      view=ViewConfig(mode="3d", size=(1280, 720)), seconds=120.0)
    run_window(cfg)          # tanktool.game.app

Fields a player can change in the menu (arena, vehicle, opponents, view) are the
menu's first values; the rest (rules, network, recording) hold for the whole run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: the default window size (also the settings' default resolution)
DEFAULT_SIZE = (1280, 720)


@dataclass
class Opponents:
    """The computer tanks: how many, how good (None: the menu's last choice, "easy" on
    a first start), and who drives them ("agent": the ``sim.agents`` computer player;
    "scripted": the old scripted bot); ``bots``: bot specs (``play --bot``) driving the
    first computer tanks, the others as above."""

    count: int = 3
    difficulty: str | None = None
    driver: str = "agent"
    bots: tuple[str, ...] = ()


@dataclass
class ViewConfig:
    """How the match is shown: "3d" or "top", the window size, full screen, and the
    graphics preset for this run (None: the settings page's)."""

    mode: str = "3d"
    size: tuple[int, int] = DEFAULT_SIZE
    fullscreen: bool = False
    quality: str | None = None


@dataclass
class NetworkConfig:
    """A network match started at once: "host" (listen on ``address``) or "join" (the
    session at ``address``), with the player's name and the session's password."""

    mode: str
    address: str
    name: str | None = None
    password: str | None = None


@dataclass
class Recording:
    """``record``: every local match is recorded there (the file holds the last one);
    ``replay``: a ``sim.replay.Replay`` shown instead of the menu (``replay_name``: its file)."""

    record: Path | None = None
    replay: Any = None
    replay_name: str = ""


@dataclass
class MatchConfig:
    """Everything a match in the window needs.

    ``seconds``: each local match ends after that much simulated time (None: when the
    player quits); ``rules``: a ``sim.rules.Rules`` (None: the default rules);
    ``sound``: open the audio device (off in tests and on machines without one).
    """

    arena: str | None = None
    vehicle: str | None = None
    opponents: Opponents = field(default_factory=Opponents)
    seed: int = 0
    rules: Any = None
    seconds: float | None = None
    view: ViewConfig = field(default_factory=ViewConfig)
    network: NetworkConfig | None = None
    recording: Recording = field(default_factory=Recording)
    sound: bool = True
    #: ``--watch MODEL``: a ``game.watch.ModelWatch`` whose re-imports replace the arena
    #: while the window is open (None: no watching)
    watch: Any = None
