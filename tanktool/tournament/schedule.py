"""What a tournament plays: its settings (``TournamentConfig``), the players
(``Player``: a bot spec with the source of its file, so that a worker on another
machine can load it) and the round robin (``schedule``: one ``MatchTask`` per match,
seeds and sides fixed before anything runs, so that the results do not depend on
where or in what order the matches are played)."""

from __future__ import annotations

import hashlib
import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..bots import BUILTIN, DEFAULT_BUDGET
from ..sim.bots.lineup import load_checked
from ..errors import TanktoolError

#: a bot file shipped to workers may be at most this large [bytes]
MAX_BOT_SOURCE = 4 << 20


@dataclass(frozen=True)
class TournamentConfig:
    """A tournament's settings.

    bots : bot specs, built-in names or ``FILE.py:Class`` (at least two)
    arenas, vehicles : bundled names or folders; every pairing plays on each
    matches : matches per pairing, arena and vehicle
    seconds : simulated seconds per match
    first_seed : match k of a pairing uses seed ``first_seed + k``
    boot : bootstrap resamples for the Elo intervals
    budget : seconds a bot's call may take before it is counted over budget
    """

    bots: tuple[str, ...]
    arenas: tuple[str, ...] = ("box",)
    vehicles: tuple[str, ...] = ("light",)
    matches: int = 2
    seconds: float = 60.0
    first_seed: int = 0
    boot: int = 200
    budget: float = DEFAULT_BUDGET

    def check(self) -> None:
        """Refuse settings that cannot make a tournament (TanktoolError)."""
        if len(self.bots) < 2:
            raise TanktoolError(f"a tournament needs at least two bots (--bot, repeated), got {len(self.bots)}")
        if not self.arenas or not self.vehicles:
            raise TanktoolError("a tournament needs at least one arena and one vehicle")
        if self.matches < 1:
            raise TanktoolError(f"--matches must be at least 1, got {self.matches}")
        if not (self.seconds > 0 and math.isfinite(self.seconds) and self.seconds <= 86400):
            raise TanktoolError(f"--seconds must be a number of seconds in (0, 86400], got {self.seconds}")
        if self.boot < 0:
            raise TanktoolError(f"--boot must be 0 or more, got {self.boot}")


@dataclass(frozen=True)
class Player:
    """One bot of the tournament: its ``name`` in tables (unique), the ``spec`` as
    given, and for a file its absolute ``path``, ``cls`` name, ``sha256`` and
    ``source`` text (what a worker loads when it cannot read the same file)."""

    name: str
    spec: str
    path: str | None = None
    cls: str | None = None
    sha256: str | None = None
    source: str | None = field(default=None, repr=False)

    def public(self) -> dict:
        """What the report says about the player (no absolute path: reports compare
        equal wherever the tournament ran)."""
        d = {"name": self.name, "spec": self.spec}
        if self.sha256:
            d["sha256"] = self.sha256
        return d


#: the scripted baseline (``sim.driver.ScriptedDriver``): a player, not a bot (it reads
#: the world), kept so that the difficulty ladder (bench/ladder.py) measures against it
SCRIPTED = "scripted"


def resolve_players(specs: list[str] | tuple[str, ...]) -> list[Player]:
    """Load every spec once here (a bad spec is one error before any match runs) and
    name the players uniquely (``Sniper``, ``Sniper#2``)."""
    players: list[Player] = []
    seen: dict[str, int] = {}
    for spec in specs:
        if spec.strip() == SCRIPTED:
            seen[SCRIPTED] = seen.get(SCRIPTED, 0) + 1
            players.append(Player(SCRIPTED if seen[SCRIPTED] == 1 else f"{SCRIPTED}#{seen[SCRIPTED]}", SCRIPTED))
            continue
        maker = load_checked(spec)
        name = maker.name
        seen[name] = seen.get(name, 0) + 1
        if seen[name] > 1:
            name = f"{name}#{seen[name]}"
        if spec.strip() in BUILTIN:
            players.append(Player(name, spec.strip()))
            continue
        path_text, sep, _ = spec.strip().rpartition(":")
        path = Path(path_text if sep and path_text.endswith(".py") else spec.strip()).resolve()
        data = path.read_bytes()
        if len(data) > MAX_BOT_SOURCE:
            raise TanktoolError(f"bot {spec!r}: {path} is larger than {MAX_BOT_SOURCE >> 20} MiB")
        players.append(Player(name, spec.strip(), str(path), maker.make.__name__,
                              hashlib.sha256(data).hexdigest(), data.decode("utf-8", "replace")))
    return players


@dataclass(frozen=True)
class MatchTask:
    """One match: players ``a`` and ``b`` (indices into the tournament's players),
    the arena and vehicle refs, match number ``k`` of the pairing, its ``seed``,
    and which tank ``a`` drives (``a_tank``: 0 on even k, so neither side keeps the
    better spawn)."""

    index: int
    a: int
    b: int
    arena: str
    vehicle: str
    k: int
    seed: int
    a_tank: int
    seconds: float
    players: tuple[Player, Player]
    budget: float = DEFAULT_BUDGET
    record: bool = True

    @property
    def cell(self) -> tuple[int, int, str, str]:
        return (self.a, self.b, self.arena, self.vehicle)

    def replay_name(self) -> str:
        """The replay's file name: arena, vehicle, the two players, the match number."""
        def safe(text: str) -> str:
            return "".join(c if c.isalnum() or c in "-_." else "_" for c in text)[:40]

        p, q = self.players
        return (f"{self.index:04d}-{safe(Path(self.arena).name)}-{safe(Path(self.vehicle).name)}-"
                f"{safe(p.name)}-vs-{safe(q.name)}-{self.k}.ttr")


def schedule(config: TournamentConfig, players: list[Player], record: bool = True) -> list[MatchTask]:
    """The round robin: every pair of players, on every arena and vehicle,
    ``config.matches`` times."""
    tasks = []
    for arena in config.arenas:
        for vehicle in config.vehicles:
            for a, b in itertools.combinations(range(len(players)), 2):
                for k in range(config.matches):
                    tasks.append(MatchTask(len(tasks), a, b, arena, vehicle, k, config.first_seed + k, k % 2,
                                           float(config.seconds), (players[a], players[b]), config.budget, record))
    return tasks
