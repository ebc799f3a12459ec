"""Match replays: a match is its seed, its setup and every tank's commands.

The simulation is deterministic, so a recorded match played back with the same
arena, vehicle and commands reaches the same state bit for bit.  The recorder wraps
the match's drivers (keyboard, agent, scripted bot, peer alike: all produce
``Command`` values) and keeps a command only when it differs from that tank's
previous one; playback swaps the drivers for ones that read the tape.

File layout (``.ttr``, all integers little-endian)::

    bytes 0-3   b"TTRP"                  magic
    byte  4     1                        format version
    bytes 5-8   u32 H                    header length
    9 .. 9+H    UTF-8 JSON header        setup, fingerprints, final-state digest
    9+H ..      zlib stream              the command changes, column by column:
                  u32[n] step deltas, u16[n] tank, f64[n] advance, f64[n] rotate,
                  f64[n] strafe, u8[n] fire
                (each multi-byte column stored as byte planes -- all first bytes,
                then all second bytes, ... -- which zlib packs much better)

A change record (step k, tank i, command c) means tank i's driver returned c before
step k+1 (when ``world.steps == k``) and keeps returning it until the next record of
tank i; before its first record a tank is idle.  The header carries the world's
random-generator state right after the drivers were made (so playback does not
depend on how they consumed it), fingerprints of the walls, spawns and vehicle (a
changed arena is refused, not silently replayed into another match), the match's
rules (``rules``: ``sim.rules.Rules.to_dict``; a recording without them was made
before issue 19 and plays back under ``Rules.classic()``), and a sha256 of the final
world state and scores so that playback can say whether it matched.
"""

from __future__ import annotations

import base64
import hashlib
import json
import math
import os
import struct
import zlib
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

from .. import __version__
from ..errors import FormatError, TanktoolError
from .commands import IDLE, Command

if TYPE_CHECKING:  # pragma: no cover
    from .body import Tank, TankSpec
    from .match import ArenaInfo, MatchResult
    from .rules import Rules
    from .world import World

MAGIC = b"TTRP"
VERSION = 1
_PREFIX = struct.Struct("<4sBI")
#: bytes per change record before compression
RECORD_BYTES = 4 + 2 + 3 * 8 + 1


# ---------------------------------------------------------------- fingerprints

def _plain(value: Any) -> Any:
    """JSON-ready nested lists; floats keep every bit (json writes repr)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _sha(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()


def arena_fingerprint(arena: "ArenaInfo") -> str:
    """sha256 of what the simulation sees of an arena: walls (with the auxiliary
    rectangle), spawn points and bounds."""
    walls = arena.walls.all_segments() if hasattr(arena.walls, "all_segments") else arena.walls
    bounds = None if arena.bounds is None else np.asarray(arena.bounds, dtype=np.float64)
    return _sha([_plain(np.asarray(walls, dtype=np.float64)), _plain(np.asarray(arena.spawns, dtype=np.float64)),
                 _plain(bounds)])


def spec_fingerprint(spec: "TankSpec") -> str:
    """sha256 of a TankSpec's defining fields (geometry and physics)."""
    return _sha({f.name: _plain(getattr(spec, f.name)) for f in fields(spec) if f.init})


def state_digest(world: "World") -> str:
    """sha256 of every evolving number of the world and the tanks' scores: equal
    digests mean equal states bit for bit (repr of a float is exact)."""
    scores = [(t.kills, t.deaths, t.shots, t.hits, t.wall_bumps, repr(t.distance)) for t in world.tanks]
    return hashlib.sha256(repr((world.state(), scores)).encode()).hexdigest()


# ---------------------------------------------------------------- the tape

@dataclass
class Replay:
    """A recorded match.

    header : setup (``arena``, ``vehicle``, ``bots``, ``seconds``, ``seed``, ``dt``,
             ``integrator``, ``options`` for run_match, ``rules``), fingerprints,
             ``rng_state``, ``final_state`` digest
    steps : (n,) int64, the world step count at which each change was made
    tanks : (n,) int64, tank index of each change
    values : (n, 3) float64, advance / rotate / strafe
    fire : (n,) bool
    """

    header: dict[str, Any]
    steps: np.ndarray
    tanks: np.ndarray
    values: np.ndarray
    fire: np.ndarray

    def __len__(self) -> int:
        return len(self.steps)

    def timeline(self, tank: int) -> tuple[list[int], list[Command]]:
        """One tank's change steps and commands, in order."""
        idx = np.flatnonzero(self.tanks == tank)
        return ([int(s) for s in self.steps[idx]],
                [Command(*(float(v) for v in self.values[k]), bool(self.fire[k])) for k in idx])

    def restore_rng(self, world: "World") -> None:
        """Put the world's generator where it was when the recording started."""
        raw = base64.b64decode(self.header["rng_state"])
        words = struct.unpack(f"<{len(raw) // 4}I", raw)
        world.rng.setstate((3, tuple(words), None))

    def wrap(self, world: "World", drivers: Sequence[Any] = ()) -> list["ReplayDriver"]:
        """``run_match``'s ``wrap_drivers`` hook: ignore the match's own drivers,
        restore the recorded generator state and drive every tank from the tape."""
        if len(world.tanks) != int(self.header["bots"]):
            raise TanktoolError(f"replay has {self.header['bots']} tanks, the world {len(world.tanks)}")
        self.restore_rng(world)
        self.apply_names(world)
        return [ReplayDriver(*self.timeline(i)) for i in range(len(world.tanks))]

    def apply_names(self, world: "World") -> None:
        """Give the tanks the names they had in the recording (a window match calls the
        player's tank "you"), so reports and scoreboards read the same."""
        names = self.header.get("names")
        if isinstance(names, list) and len(names) == len(world.tanks) and all(isinstance(n, str) for n in names):
            for t, n in zip(world.tanks, names):
                t.name = n


class ReplayDriver:
    """Returns the recorded command of one tank for the world's current step."""

    def __init__(self, steps: list[int], commands: list[Command]) -> None:
        self.steps = steps
        self.commands = commands
        self.cursor = 0
        self.command: Command = IDLE

    def __call__(self, world: "World", tank: "Tank") -> Command:
        k = world.steps
        while self.cursor < len(self.steps) and self.steps[self.cursor] <= k:
            self.command = self.commands[self.cursor]
            self.cursor += 1
        return self.command


class _RecordingDriver:
    def __init__(self, inner: Callable, recorder: "Recorder", index: int) -> None:
        self.inner = inner
        self.recorder = recorder
        self.index = index

    def __call__(self, world: "World", tank: "Tank") -> Command | None:
        cmd = self.inner(world, tank)
        self.recorder.record(world.steps, self.index, IDLE if cmd is None else cmd)
        return cmd

    @property
    def stats(self) -> Any:
        """The wrapped bot's ``BotStats`` (None for other drivers): a recorded match
        reports its bots' failures and timing as an unrecorded one does."""
        return getattr(self.inner, "stats", None)


@dataclass
class Recorder:
    """Collects command changes; ``wrap`` is ``run_match``'s ``wrap_drivers`` hook."""

    steps: list[int] = field(default_factory=list)
    tanks: list[int] = field(default_factory=list)
    values: list[tuple[float, float, float]] = field(default_factory=list)
    fire: list[bool] = field(default_factory=list)
    rng_state: str = ""
    last: list[tuple[float, float, float, bool]] = field(default_factory=list)

    def wrap(self, world: "World", drivers: Sequence[Callable]) -> list[Callable]:
        version, words, _gauss = world.rng.getstate()
        if version != 3:  # pragma: no cover - CPython's Mersenne Twister
            raise TanktoolError("cannot record: unexpected random generator state")
        self.rng_state = base64.b64encode(struct.pack(f"<{len(words)}I", *words)).decode()
        self.last = [IDLE.to_tuple()] * len(drivers)
        return [_RecordingDriver(d, self, i) for i, d in enumerate(drivers)]

    def record(self, step: int, tank: int, command: Command) -> None:
        t = command.to_tuple()
        # compare bit patterns, not values: -0.0 == 0.0 but must replay as itself
        if repr(t) == repr(self.last[tank]):
            return
        self.last[tank] = t
        self.steps.append(step)
        self.tanks.append(tank)
        self.values.append(t[:3])
        self.fire.append(t[3])

    def replay(self, header: dict[str, Any]) -> Replay:
        """The recording as a :class:`Replay` with ``header`` (plus the rng state)."""
        h = dict(header)
        h["rng_state"] = self.rng_state
        return Replay(h, np.asarray(self.steps, dtype=np.int64), np.asarray(self.tanks, dtype=np.int64),
                      np.asarray(self.values, dtype=np.float64).reshape(-1, 3), np.asarray(self.fire, dtype=bool))


# ---------------------------------------------------------------- bytes

def _planes(a: np.ndarray) -> bytes:
    b = np.ascontiguousarray(a).view(np.uint8).reshape(len(a), a.dtype.itemsize)
    return b.T.tobytes()


def _unplanes(buf: bytes, n: int, dtype: str) -> np.ndarray:
    size = np.dtype(dtype).itemsize
    b = np.frombuffer(buf, dtype=np.uint8).reshape(size, n).T.copy()
    return b.view(dtype).reshape(n)


def encode(replay: Replay) -> bytes:
    """The replay file's bytes."""
    n = len(replay)
    steps = replay.steps.astype(np.int64)
    deltas = np.diff(steps, prepend=0)
    if n and (deltas.min() < 0 or steps.max() >= 2 ** 32):
        raise TanktoolError("replay steps must be non-decreasing and below 2**32")
    body = b"".join([
        _planes(deltas.astype("<u4")), _planes(replay.tanks.astype("<u2")),
        _planes(replay.values[:, 0].astype("<f8")), _planes(replay.values[:, 1].astype("<f8")),
        _planes(replay.values[:, 2].astype("<f8")), replay.fire.astype(np.uint8).tobytes(),
    ])
    header = dict(replay.header)
    header["changes"] = n
    head = json.dumps(header, sort_keys=True, separators=(",", ":")).encode()
    return _PREFIX.pack(MAGIC, VERSION, len(head)) + head + zlib.compress(body, 9)


#: what a replay may ask for: a day of simulated time (play's --seconds limit), the
#: tanks play allows, and command data at most this many times its compressed size
MAX_SECONDS = 86400.0
MAX_BOTS = 64
MAX_INFLATION = 64
MAX_REPLAY_BYTES = 256 << 20
DT_RANGE = (1e-4, 1.0)
#: the header fields every replay has (match_header writes them; playback reads them)
HEADER_FIELDS = ("bots", "steps", "seconds", "seed", "dt", "integrator", "rng_state", "changes", "final_state")
#: keys of ``options`` that run_match takes, and the values each may have
_OPTION_VALUES = {"bot": ("agent", "scripted"), "difficulty": ("easy", "normal", "hard")}
#: the match end's options: (exclusive low, high, whole number), as ``play`` accepts them
_LIMIT_OPTIONS = {"time_limit": (0.0, 86400.0, False), "score_limit": (0.0, 1_000_000.0, True)}


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def check_header(header: dict[str, Any], where: str) -> None:
    """Refuse a replay header whose setup fields are missing, of the wrong type or out
    of range (FormatError naming ``where`` and the field): playback then never meets
    a NaN, a zero dt, a year of simulated time or an unknown integrator."""
    from .world import INTEGRATORS

    def bad(key: str, what: str) -> FormatError:
        return FormatError(f"{where}: replay header '{key}' {what}, got {header.get(key)!r:.60}")

    bots = header["bots"]
    if not (_is_int(bots) and 1 <= bots <= MAX_BOTS):
        raise bad("bots", f"must be a count of tanks from 1 to {MAX_BOTS}")
    dt = header["dt"]
    if not (_is_number(dt) and DT_RANGE[0] <= dt <= DT_RANGE[1]):
        raise bad("dt", f"must be a time step from {DT_RANGE[0]:g} to {DT_RANGE[1]:g} s")
    steps = header["steps"]
    if not (_is_int(steps) and 1 <= steps and steps * dt <= MAX_SECONDS):
        raise bad("steps", f"must be a count of steps of at most {MAX_SECONDS:g} s of simulated time")
    seconds = header["seconds"]  # play reads it: required (decode checks it is there)
    if not (_is_number(seconds) and 0 < seconds <= MAX_SECONDS and int(round(seconds / dt)) == steps):
        raise bad("seconds", f"must be {steps} steps x dt {dt:g} s")
    if not (_is_int(header["seed"]) and abs(header["seed"]) < 2 ** 64):
        raise bad("seed", "must be an integer")
    if header["integrator"] not in INTEGRATORS:
        raise bad("integrator", f"must be one of {', '.join(INTEGRATORS)}")
    rng = header["rng_state"]
    try:
        raw = base64.b64decode(rng, validate=True) if isinstance(rng, str) else b""
    except ValueError:
        raw = b""
    if len(raw) != 625 * 4 or struct.unpack_from("<I", raw, 624 * 4)[0] > 624:
        raise bad("rng_state", "must be the base64 state of the random generator (625 words)")
    fs = header["final_state"]
    if not (isinstance(fs, str) and len(fs) <= 128):
        raise bad("final_state", "must be the final state's sha256 (a string)")
    for key in ("arena_ref", "vehicle_ref", "arena", "vehicle", "arena_sha256", "vehicle_sha256"):
        v = header.get(key)
        if v is not None and not (isinstance(v, str) and len(v) <= 4096 and "\0" not in v):
            raise bad(key, "must be a string")
    names = header.get("names")
    if names is not None and not (isinstance(names, list) and len(names) == bots
                                  and all(isinstance(n, str) and len(n) <= 64 for n in names)):
        raise bad("names", f"must be {bots} tank names")
    options = header.get("options")
    if options is not None:
        if not isinstance(options, dict):
            raise bad("options", "must be an object")
        for k, v in options.items():
            if k in _LIMIT_OPTIONS:
                lo, hi, whole = _LIMIT_OPTIONS[k]
                number = _is_int(v) if whole else (isinstance(v, (int, float)) and not isinstance(v, bool))
                if not (number and math.isfinite(v) and lo < v <= hi):
                    raise bad(f"options.{k}", f"must be a {'whole ' if whole else ''}number in ({lo:g}, {hi:g}]")
                continue
            if k not in _OPTION_VALUES or v not in _OPTION_VALUES[k]:
                allowed = "; ".join(f"{k2}: {', '.join(vs)}" for k2, vs in _OPTION_VALUES.items())
                raise FormatError(f"{where}: replay header 'options' {k}={v!r:.40} is not a match option "
                                  f"({allowed}; time_limit, score_limit)")
    player = header.get("player")
    if player is not None and not (_is_int(player) and 0 <= player < bots):
        raise bad("player", f"must be a tank index 0..{bots - 1}")


def decode(data: bytes, path: str | os.PathLike = "<replay>") -> Replay:
    """Parse replay bytes; FormatError names ``path`` and the byte offset.

    Everything is bounded before it is allocated: the header's size and nesting, its
    fields (:func:`check_header`), the number of changes (no more than the steps and
    tanks allow) and the command data, inflated to at most its declared size and to at
    most ``MAX_INFLATION`` times its compressed bytes (a zlib bomb is refused)."""
    from ..formats.limits import MAX_DEPTH, MAX_REPLAY_HEADER_BYTES, nesting_depth

    if len(data) < _PREFIX.size or data[:4] != MAGIC:
        raise FormatError(f"{path}: byte 0: not a tanktool replay (expected magic {MAGIC.decode()})")
    _, version, hlen = _PREFIX.unpack_from(data)
    if version != VERSION:
        raise FormatError(f"{path}: byte 4: replay format version {version}, this tool reads {VERSION}")
    start = _PREFIX.size
    if start + hlen > len(data):
        raise FormatError(f"{path}: byte 5: header of {hlen} bytes runs past the end of the file ({len(data)} bytes)")
    if hlen > MAX_REPLAY_HEADER_BYTES:
        raise FormatError(f"{path}: byte 5: header of {hlen:,} bytes, more than {MAX_REPLAY_HEADER_BYTES:,}")
    try:
        header = json.loads(data[start:start + hlen].decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:  # JSONDecodeError; ints of over 4300 digits
        pos = getattr(e, "pos", getattr(e, "start", 0))
        raise FormatError(f"{path}: byte {start + pos}: replay header is not valid JSON") from None
    except RecursionError:
        raise FormatError(f"{path}: byte {start}: replay header is nested deeper than {MAX_DEPTH} levels") from None
    if not isinstance(header, dict):
        raise FormatError(f"{path}: byte {start}: replay header must be a JSON object")
    if nesting_depth(header) > MAX_DEPTH:
        raise FormatError(f"{path}: byte {start}: replay header is nested deeper than {MAX_DEPTH} levels")
    missing = [k for k in HEADER_FIELDS if k not in header]
    if missing:
        raise FormatError(f"{path}: byte {start}: replay header lacks {', '.join(missing)}")
    check_header(header, f"{path}: byte {start}")
    n = header["changes"]
    bots = header["bots"]
    if not (_is_int(n) and 0 <= n <= header["steps"] * bots):
        raise FormatError(f"{path}: byte {start}: replay header 'changes' must be a count of command changes "
                          f"(at most one per tank and step), got {n!r:.40}")
    body_at = start + hlen
    packed = data[body_at:]
    want = n * RECORD_BYTES
    if want > MAX_INFLATION * len(packed) + (1 << 20):
        raise FormatError(f"{path}: byte {body_at}: {n:,} changes ({want:,} bytes) cannot come from "
                          f"{len(packed):,} compressed bytes (a zlib bomb?)")
    try:
        z = zlib.decompressobj()
        body = z.decompress(packed, want + 1)
        if len(body) <= want and not z.eof:
            body += z.flush()
    except zlib.error as e:
        raise FormatError(f"{path}: byte {body_at}: command data is damaged ({e})") from None
    if len(body) <= want and not z.eof:
        raise FormatError(f"{path}: byte {body_at}: command data is damaged (the compressed stream is cut short)")
    if len(body) != want:
        got = f"more than {want}" if len(body) > want else str(len(body))
        raise FormatError(f"{path}: byte {body_at}: command data holds {got} bytes, "
                          f"{n} changes need {want}")
    o = 0
    cols = []
    for dtype in ("<u4", "<u2", "<f8", "<f8", "<f8"):
        size = np.dtype(dtype).itemsize * n
        cols.append(_unplanes(body[o:o + size], n, dtype))
        o += size
    fire = np.frombuffer(body[o:o + n], dtype=np.uint8)
    steps = np.cumsum(cols[0].astype(np.int64))
    tanks = cols[1].astype(np.int64)
    values = np.column_stack(cols[2:5]) if n else np.zeros((0, 3))
    if n and (tanks.max() >= bots or steps.max() >= int(header["steps"]) or fire.max() > 1):
        raise FormatError(f"{path}: byte {body_at}: a command names a tank or step outside the match")
    if n and not np.isfinite(values).all():
        raise FormatError(f"{path}: byte {body_at}: a command strength is not finite")
    if n and (np.abs(values) > 1.0).any():
        raise FormatError(f"{path}: byte {body_at}: a command strength is outside -1..1")
    return Replay(header, steps, tanks, values, fire.astype(bool))


def write_replay(path: str | os.PathLike, replay: Replay) -> int:
    """Write atomically; returns the file size in bytes."""
    from ..formats.bundle import atomic_write_bytes

    data = encode(replay)
    atomic_write_bytes(path, data)
    return len(data)


def read_replay(path: str | os.PathLike) -> Replay:
    from ..formats.bundle import read_input

    return decode(read_input(path, "a replay file", limit=MAX_REPLAY_BYTES), path)


# ---------------------------------------------------------------- matches

def record_match(arena: "ArenaInfo", spec: "TankSpec", *, bots: int, seconds: float, seed: int,
                 arena_ref: str | None = None, vehicle_ref: str | None = None,
                 on_progress: Callable[[int], None] | None = None,
                 wrap_drivers: Callable[["World", list], list] | None = None,
                 extra: dict[str, Any] | None = None,
                 **options: Any) -> tuple["MatchResult", Replay]:
    """Run a match with :func:`run_match` (``options``: integrator, dt, bot kind,
    difficulty, ...) and record it; ``wrap_drivers`` changes the drivers before the
    recorder wraps them (``play --bot``), ``extra`` goes into the header."""
    from .match import run_match

    rec = Recorder()

    def wrap(world: "World", drivers: list) -> list:
        return rec.wrap(world, drivers if wrap_drivers is None else wrap_drivers(world, drivers))

    result = run_match(arena, spec, bots=bots, seconds=seconds, seed=seed, on_progress=on_progress,
                       wrap_drivers=wrap, **options)
    w = result.world
    if w.match.over:            # ended on a limit: the recording is as long as the match was
        seconds = w.steps * w.dt
    header = match_header(arena, spec, w, seconds=seconds, seed=seed, arena_ref=arena_ref,
                          vehicle_ref=vehicle_ref, options=options, winner=result.report.get("winner"),
                          **(extra or {}))
    return result, rec.replay(header)


def match_header(arena: "ArenaInfo", spec: "TankSpec", world: "World", *, seconds: float, seed: int,
                 arena_ref: str | None = None, vehicle_ref: str | None = None,
                 options: dict[str, Any] | None = None, winner: Any = None, **extra: Any) -> dict[str, Any]:
    """The replay header of a finished match on ``world`` (``extra`` keys are added:
    the game window adds ``source`` and ``player``)."""
    header = {
        "format": "tanktool-replay", "tool_version": __version__,
        "arena": arena.name, "arena_ref": arena_ref if arena_ref is not None else
        (str(arena.path) if arena.path is not None else arena.name),
        "arena_sha256": arena_fingerprint(arena),
        "vehicle": spec.name, "vehicle_ref": vehicle_ref, "vehicle_sha256": spec_fingerprint(spec),
        "bots": len(world.tanks), "names": world.names, "seconds": float(seconds), "seed": int(seed),
        "steps": int(world.steps), "dt": world.dt, "integrator": world.integrator,
        "options": {k: v for k, v in (options or {}).items() if k not in ("dt", "integrator", "rules")},
        "rules": world.rules.to_dict(),
        "final_state": state_digest(world),
        "winner": winner,
    }
    header.update(extra)
    return header


def replay_rules(header: dict[str, Any]) -> "Rules":
    """The rules a recording was made under: its ``rules``, or, for a recording made
    before matches had rules (issue 19), ``Rules.classic()``."""
    from .rules import Rules

    d = header.get("rules")
    if d is None:
        return Rules.classic()
    try:
        return Rules.from_dict(d, "replay header: rules")
    except (TypeError, ValueError) as e:
        raise FormatError(str(e)) from None


@dataclass
class Playback:
    """What :func:`play_replay` produced: the match result and whether its final
    state is the recorded one."""

    result: "MatchResult"
    digest: str
    matches: bool


def play_replay(replay: Replay, arena: "ArenaInfo", spec: "TankSpec",
                on_progress: Callable[[int], None] | None = None) -> Playback:
    """Play a replay back on ``arena`` with ``spec`` (checked against the
    recording's fingerprints) and compare the final state."""
    from .match import run_match

    h = replay.header
    if h.get("arena_sha256") and arena_fingerprint(arena) != h["arena_sha256"]:
        raise TanktoolError(f"arena {arena.name!r} is not the one the replay was recorded on "
                            f"(its walls, spawns or bounds differ)")
    if h.get("vehicle_sha256") and spec_fingerprint(spec) != h["vehicle_sha256"]:
        raise TanktoolError(f"vehicle {spec.name!r} is not the one the replay was recorded with")
    seconds = float(h["seconds"])
    dt = float(h["dt"])
    if int(round(seconds / dt)) != int(h["steps"]) or not math.isfinite(seconds):
        raise TanktoolError(f"replay header: seconds {seconds} and dt {dt} do not give {h['steps']} steps")
    options = {k: v for k, v in dict(h.get("options") or {}).items() if k != "rules"}
    result = run_match(arena, spec, bots=int(h["bots"]), seconds=seconds, seed=int(h["seed"]), dt=dt,
                       integrator=str(h["integrator"]), on_progress=on_progress, wrap_drivers=replay.wrap,
                       rules=replay_rules(h), **options)
    digest = state_digest(result.world)
    return Playback(result, digest, digest == h["final_state"])
