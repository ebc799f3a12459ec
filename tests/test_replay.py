"""Replays: a recorded match played back reaches the same state bit for bit."""

from __future__ import annotations

import json
import struct
import zlib

import numpy as np
import pytest

from tanktool.errors import FormatError, TanktoolError
from tanktool.sim import Command
from tanktool.sim.match import ArenaInfo, load_match_arena, load_tank_spec
from tanktool.sim.replay import (
    MAGIC,
    RECORD_BYTES,
    Recorder,
    decode,
    encode,
    play_replay,
    read_replay,
    record_match,
    state_digest,
    write_replay,
)


def _without_timing(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "timing"}


@pytest.fixture(scope="module")
def box():
    return load_match_arena("box"), load_tank_spec("light")


@pytest.fixture(scope="module", params=["agent", "scripted"])
def recorded(request, box):
    arena, spec = box
    result, replay = record_match(arena, spec, bots=4, seconds=8.0, seed=5, bot=request.param,
                                  arena_ref="box", vehicle_ref="light")
    return result, replay


def test_replay_reaches_the_same_state_and_report(recorded, box, tmp_path):
    result, replay = recorded
    arena, spec = box
    path = tmp_path / "m.ttr"
    size = write_replay(path, replay)
    assert size == path.stat().st_size
    back = read_replay(path)
    playback = play_replay(back, arena, spec)
    assert playback.matches and playback.digest == replay.header["final_state"] == state_digest(result.world)
    # bit for bit: every evolving number, the generator, the scores, the whole report
    a, b = result.world.snapshot(), playback.result.world.snapshot()
    assert repr(a) == repr(b)
    assert _without_timing(playback.result.report) == _without_timing(result.report)
    assert playback.result.report["events"], "a match with no events proves little"
    assert playback.result.trails == result.trails


def test_the_file_is_compact_changes_only(recorded):
    result, replay = recorded
    steps, bots = replay.header["steps"], replay.header["bots"]
    assert steps == 960 and bots == 4
    # bots hold a command for a think period: far fewer changes than steps x tanks
    assert 0 < len(replay) < steps * bots / 4
    data = encode(replay)
    body = len(data) - 9 - struct.unpack_from("<I", data, 5)[0]
    assert body < len(replay) * RECORD_BYTES            # zlib over byte planes does pack it
    # every recorded change is a real change of that tank's command
    for i in range(bots):
        steps_i, cmds = replay.timeline(i)
        assert steps_i == sorted(steps_i)
        assert all(repr(p.to_tuple()) != repr(q.to_tuple()) for p, q in zip(cmds, cmds[1:]))


def test_encode_decode_round_trip_keeps_every_bit():
    rec = Recorder()

    class W:
        import random
        rng = random.Random(3)

    rec.wrap(W, [None, None])
    cmds = [(0, 0, Command(1.0, -0.0, 0.1 + 0.2, True)), (0, 1, Command(-1.0, 1e-300, -0.5)),
            (7, 0, Command(1.0, 0.0, 0.1 + 0.2, True)), (9, 1, Command(-1.0, 1e-300, -0.5))]
    for step, tank, c in cmds:
        rec.record(step, tank, c)
    replay = rec.replay({"bots": 2, "steps": 10, "seconds": 0.1, "seed": 3, "dt": 0.01, "integrator": "euler",
                         "final_state": "x"})
    # -0.0 -> 0.0 is a change (different bits); an identical command is not
    assert len(replay) == 3 and list(replay.steps) == [0, 0, 7]
    back = decode(encode(replay))
    assert back.values.tobytes() == replay.values.tobytes()
    assert np.array_equal(back.steps, replay.steps) and np.array_equal(back.tanks, replay.tanks)
    assert np.array_equal(back.fire, replay.fire)
    assert back.header["rng_state"] == replay.header["rng_state"]


def test_changed_arena_is_refused(recorded, box):
    _, replay = recorded
    arena, spec = box
    moved = ArenaInfo(arena.name, arena.walls, arena.spawns + 0.5, arena.path, arena.bounds)
    with pytest.raises(TanktoolError, match="not the one the replay was recorded on"):
        play_replay(replay, moved, spec)
    with pytest.raises(TanktoolError, match="not the one the replay was recorded with"):
        play_replay(replay, arena, load_tank_spec("heavy"))


def _bad(data: bytes, tmp_path, match: str) -> None:
    p = tmp_path / "bad.ttr"
    p.write_bytes(data)
    with pytest.raises(FormatError, match=match) as e:
        read_replay(p)
    assert str(p) in str(e.value)


def test_damaged_files_name_the_byte(recorded, tmp_path):
    _, replay = recorded
    data = encode(replay)
    hlen = struct.unpack_from("<I", data, 5)[0]
    _bad(b"PK\x03\x04rest", tmp_path, "byte 0: not a tanktool replay")
    _bad(data[:4] + b"\x09" + data[5:], tmp_path, "byte 4: replay format version 9")
    _bad(data[:9 + hlen - 10], tmp_path, f"byte 5: header of {hlen} bytes runs past the end")
    _bad(data[:9] + b"x" + data[10:], tmp_path, r"byte \d+: replay header is not valid JSON")
    _bad(data[:-20], tmp_path, rf"byte {9 + hlen}: command data is damaged")
    head = json.loads(data[9:9 + hlen])
    head["changes"] += 1
    h2 = json.dumps(head).encode()
    _bad(data[:4] + bytes([1]) + struct.pack("<I", len(h2)) + h2 + data[9 + hlen:], tmp_path,
         "command data holds")
    del head["rng_state"]
    h3 = json.dumps(head).encode()
    _bad(data[:5] + struct.pack("<I", len(h3)) + h3 + data[9 + hlen:], tmp_path, "lacks rng_state")
    # a change naming tank 9 of 4
    body = bytearray(zlib.decompress(data[9 + hlen:]))
    n = replay.header.get("changes", len(replay))
    body[4 * n] = 9                                   # first byte plane of the first tank index
    _bad(data[:9 + hlen] + zlib.compress(bytes(body)), tmp_path, "outside the match")
    with pytest.raises(FormatError, match="no such file"):
        read_replay(tmp_path / "missing.ttr")
    assert MAGIC == b"TTRP"


# ---------------------------------------------------------------- tanktool play --record / --replay

def test_cli_record_then_replay_gives_the_same_report(tmp_path):
    from click.testing import CliRunner

    from tanktool.cli.main import cli

    tape, a, b = tmp_path / "m.ttr", tmp_path / "a.json", tmp_path / "b.json"
    run = CliRunner().invoke
    res = run(cli, ["play", "--headless", "--arena", "box", "--bots", "3", "--seconds", "4", "--seed", "2",
                    "--difficulty", "hard", "--record", str(tape), "--report", str(a)])
    assert res.exit_code == 0, res.output
    assert f"replay: {tape} (" in res.output and "command changes)" in res.output
    res = run(cli, ["play", "--replay", str(tape), "--report", str(b), "--picture", str(tmp_path / "end.png")])
    assert res.exit_code == 0, res.output
    assert "replay: final state matches the recording bit for bit" in res.output
    ra, rb = json.loads(a.read_text()), json.loads(b.read_text())
    assert _without_timing(ra) == _without_timing(rb) and ra["difficulty"] == "hard" and ra["seed"] == 2
    assert (tmp_path / "end.png").stat().st_size > 10_000
    # bad input: one line, exit 2, no traceback
    (tmp_path / "junk.ttr").write_bytes(b"not a replay")
    res = run(cli, ["play", "--replay", str(tmp_path / "junk.ttr")])
    assert res.exit_code == 2 and "junk.ttr: byte 0: not a tanktool replay" in res.output
    assert "Traceback" not in res.output
    res = run(cli, ["play", "--replay", str(tape), "--arena", "maze"])
    assert res.exit_code == 2 and "not the one the replay was recorded on" in res.output
    res = run(cli, ["play", "--record", str(tape), "--replay", str(tape)])
    assert res.exit_code == 2 and "cannot be used together" in res.output


def test_game_session_replays_to_the_recorded_state_and_screenshots(box, tmp_path):
    """The window's session (game/session.py) driven by a tape ends where the match did."""
    from click.testing import CliRunner

    from tanktool.cli.main import cli
    from tanktool.game.headless import FRAME, run_frames
    from tanktool.game.replay_session import replay_frames, replay_session

    arena, spec = box
    _, replay = record_match(arena, spec, bots=3, seconds=3.0, seed=7, arena_ref="box", vehicle_ref="light")
    session = replay_session(replay)
    assert replay_frames(replay, FRAME) == 180
    run_frames(session, 180)
    assert session.world.steps == 360 and state_digest(session.world) == replay.header["final_state"]
    tape = tmp_path / "s.ttr"
    write_replay(tape, replay)
    run = CliRunner().invoke
    shot = tmp_path / "shot.png"
    res = run(cli, ["play", "--replay", str(tape), "--headless", "--screenshot", str(shot), "--view", "top",
                    "--size", "320x240"])
    assert res.exit_code == 0, res.output
    assert f"top view of {tape} at frame 180 of 180: {shot}" in res.output and shot.stat().st_size > 1000
    res = run(cli, ["play", "--replay", str(tape), "--headless", "--screenshot", str(shot), "--frames", "181"])
    assert res.exit_code == 2 and "the recording has 180 frames" in res.output


def _with_header(data: bytes, head: dict) -> bytes:
    hlen = struct.unpack_from("<I", data, 5)[0]
    h = json.dumps(head).encode()
    return data[:5] + struct.pack("<I", len(h)) + h + data[9 + hlen:]


def test_every_required_header_field_is_checked_at_read(recorded, tmp_path):
    """A header without 'seconds' was read and then killed play with a KeyError (issue 26)."""
    from tanktool.sim.replay import HEADER_FIELDS

    _, replay = recorded
    data = encode(replay)
    hlen = struct.unpack_from("<I", data, 5)[0]
    for key in HEADER_FIELDS:
        head = json.loads(data[9:9 + hlen])
        del head[key]
        _bad(_with_header(data, head), tmp_path, f"lacks {key}")


def test_cli_replay_without_seconds_is_one_error_line(recorded, tmp_path):
    from click.testing import CliRunner

    from tanktool.cli.main import cli

    _, replay = recorded
    data = encode(replay)
    hlen = struct.unpack_from("<I", data, 5)[0]
    head = json.loads(data[9:9 + hlen])
    del head["seconds"]
    tape = tmp_path / "noseconds.ttr"
    tape.write_bytes(_with_header(data, head))
    res = CliRunner().invoke(cli, ["play", "--replay", str(tape)])
    assert res.exit_code == 2, res.output
    assert "noseconds.ttr: byte 9: replay header lacks seconds" in res.output
    assert "internal error" not in res.output and "Traceback" not in res.output
