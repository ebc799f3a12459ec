"""tanktool tournament: the round robin, Elo, serial = pool, the CLI's outputs and
errors, and a bot written only from docs/bots.md (tests/data/bots/hunter.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.sim.match import load_match_arena, load_tank_spec
from tanktool.sim.replay import play_replay, read_replay
from tanktool.tournament import TournamentConfig, fit_elo, run_tournament, schedule, resolve_players

HERE = Path(__file__).resolve().parent
HUNTER = str(HERE / "data" / "bots" / "hunter.py") + ":Hunter"
BROKEN = str(HERE / "data" / "bots" / "hunter.py") + ":Broken"


def _plain(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "timing"}


def test_elo_orders_players_by_results_and_keeps_the_mean():
    games = [(0, 1, 1.0)] * 6 + [(0, 1, 0.0)] * 2 + [(1, 2, 1.0)] * 6 + [(1, 2, 0.5)] * 2 + [(0, 2, 1.0)] * 4
    r = fit_elo(3, games)
    assert r[0] > r[1] > r[2]
    assert abs(r.mean() - 1500.0) < 1e-6
    even = fit_elo(2, [(0, 1, 0.5)] * 4)
    assert abs(even[0] - even[1]) < 1e-6


def test_the_schedule_alternates_sides_and_records_seeds():
    config = TournamentConfig(bots=("easy", "robot", "camper"), arenas=("box", "maze"), matches=3, first_seed=5)
    tasks = schedule(config, resolve_players(config.bots))
    assert len(tasks) == 3 * 2 * 3                  # pairs x arenas x matches
    assert [t.seed for t in tasks[:3]] == [5, 6, 7]
    assert [t.a_tank for t in tasks[:3]] == [0, 1, 0]
    assert len({t.replay_name() for t in tasks}) == len(tasks)


def test_serial_and_pool_give_the_same_report_and_replays():
    config = TournamentConfig(bots=("novice", HUNTER, "robot"), matches=2, seconds=12.0, boot=50)
    serial = run_tournament(config, run="serial")
    pool = run_tournament(config, run="pool", workers=2)
    assert _plain(serial.report) == _plain(pool.report)
    assert serial.replays == pool.replays
    assert serial.report["timing"]["runner"] == "serial" and pool.report["timing"]["runner"] == "pool"
    rep = serial.report
    assert [b["name"] for b in rep["bots"]] == ["novice", "Hunter", "robot"]
    assert len(rep["matches"]) == 6 and [m["seed"] for m in rep["matches"][:2]] == [0, 1]
    for t in rep["totals"]:
        assert t["wins"] + t["losses"] + t["draws"] == 2
    for row in rep["elo"]:
        assert row["lo"] <= row["elo"] <= row["hi"]


def test_the_cli_writes_json_chart_and_replays_that_play_back(tmp_path):
    out = tmp_path / "res" / "t.json"
    r = CliRunner().invoke(cli, ["tournament", "--bot", HUNTER, "--bot", "easy", "--matches", "2",
                                 "--seconds", "10", "--workers", "1", "--json", str(out), "--boot", "20"])
    assert r.exit_code == 0, r.output
    assert "Hunter vs easy" in r.output and "95 % interval" in r.output
    report = json.loads(out.read_text())
    assert report["format"] == "tanktool-tournament" and len(report["matches"]) == 2
    png = out.with_suffix(".png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    files = sorted((tmp_path / "res" / "t-replays").iterdir())
    assert [f.name for f in files] == [m["replay"] for m in report["matches"]]
    tape = read_replay(files[1])
    assert tape.header["tournament"]["players"][0]["name"] == "Hunter"
    back = play_replay(tape, load_match_arena("box"), load_tank_spec("light"))    # without the bot's file
    assert back.matches
    a_tank = report["matches"][1]["a_tank"]
    assert back.result.world.tanks[a_tank].kills == report["matches"][1]["kills"][0]


def test_the_json_and_chart_folders_are_made(tmp_path):
    out = tmp_path / "a" / "b" / "t.json"
    r = CliRunner().invoke(cli, ["tournament", "--bot", "novice", "--bot", "easy", "--matches", "1",
                                 "--seconds", "2", "--workers", "1", "--json", str(out), "--no-replays"])
    assert r.exit_code == 0, r.output
    assert out.is_file() and out.with_suffix(".png").is_file()
    assert not (tmp_path / "a" / "b" / "t-replays").exists()


def test_a_failing_bot_is_counted_and_the_tournament_goes_on():
    config = TournamentConfig(bots=(BROKEN, "novice"), matches=1, seconds=3.0, boot=0)
    rep = run_tournament(config, run="serial").report
    assert rep["bot_errors"]["Broken"] > 0
    assert rep["matches"][0]["bot_errors"][0] > 0


@pytest.mark.parametrize("args, message", [
    (["--bot", "easy"], "at least two bots"),
    (["--bot", "easy", "--bot", "nosuch"], "no such built-in bot"),
    (["--bot", "easy", "--bot", "missing.py:X"], "no such file"),
    (["--bot", "easy", "--bot", "normal", "--arena", "nowhere"], "nowhere: no such arena"),
    (["--bot", "easy", "--bot", "normal", "--matches", "0"], "--matches"),
])
def test_bad_input_is_one_error_line(args, message):
    r = CliRunner().invoke(cli, ["tournament", *args, "--no-replays"])
    assert r.exit_code == 2
    assert message in r.output
    assert "Traceback" not in r.output


def test_it_does_not_overwrite_a_file_it_did_not_write(tmp_path):
    (tmp_path / "reps").mkdir()
    name = "0000-box-light-easy-vs-normal-0.ttr"
    (tmp_path / "reps" / name).write_text("mine")
    r = CliRunner().invoke(cli, ["tournament", "--bot", "easy", "--bot", "normal", "--matches", "1",
                                 "--replays", str(tmp_path / "reps")])
    assert r.exit_code == 2 and "not a tanktool replay" in r.output
    assert (tmp_path / "reps" / name).read_text() == "mine"


def test_ray_missing_is_one_error_line(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "ray", None)        # as without the cluster extra
    r = CliRunner().invoke(cli, ["tournament", "--bot", "easy", "--bot", "novice", "--matches", "1",
                                 "--seconds", "1", "--no-replays", "--ray", "local"])
    assert r.exit_code == 2 and "pip install 'tanktool[cluster]'" in r.output


def test_the_scripted_baseline_plays_as_a_player():
    config = TournamentConfig(bots=("scripted", "novice"), matches=1, seconds=3.0, boot=0)
    rep = run_tournament(config, run="serial").report
    assert [b["name"] for b in rep["bots"]] == ["scripted", "novice"] and len(rep["matches"]) == 1


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_bot_that_cannot_be_made_is_one_error_line(tmp_path, workers):
    (tmp_path / "bad.py").write_text(
        "from tanktool.bots import Bot, Command\n"
        "class Never(Bot):\n"
        "    def __init__(self):\n"
        "        raise ValueError('no bot today')\n"
        "    def act(self, view):\n"
        "        return Command()\n"
        "class Later(Bot):\n"
        "    made = 0\n"
        "    def __init__(self):\n"
        "        type(self).made += 1\n"
        "        if type(self).made > 1:\n"
        "            raise ValueError('only once')\n"
        "    def act(self, view):\n"
        "        return Command()\n")
    for cls, message in (("Never", "making one raised ValueError: no bot today"),
                         ("Later", "making one raised ValueError: only once")):
        r = CliRunner().invoke(cli, ["tournament", "--bot", f"{tmp_path / 'bad.py'}:{cls}", "--bot", "novice",
                                     "--matches", "2", "--seconds", "1", "--no-replays", "--workers", workers])
        assert r.exit_code == 2 and message in r.output, r.output
    r = CliRunner().invoke(cli, ["play", "--headless", "--bot", f"{tmp_path / 'bad.py'}:Never", "--seconds", "1"])
    assert r.exit_code == 2 and "no bot today" in r.output


def test_a_ray_address_where_nothing_listens_is_refused_at_once():
    pytest.importorskip("ray")
    import socket

    with socket.socket() as s:          # a port that was free a moment ago
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    r = CliRunner().invoke(cli, ["tournament", "--bot", "easy", "--bot", "novice", "--matches", "1",
                                 "--seconds", "1", "--no-replays", "--ray", f"127.0.0.1:{port}"])
    assert r.exit_code == 2 and "no Ray cluster answers there" in r.output
