"""``tanktool play``: headless matches, reports, the stand-in for the window, errors."""

from __future__ import annotations

import json

from click.testing import CliRunner
from sim_fixtures import box_arena, maze_arena, write_arena_bundle

from tanktool.cli.main import cli


def _arena(tmp_path, maze=False):
    walls, spawns = maze_arena() if maze else box_arena()
    return write_arena_bundle(tmp_path / ("maze" if maze else "testbox"), walls, spawns,
                              name="maze" if maze else "testbox")


def test_headless_report(tmp_path):
    arena = _arena(tmp_path)
    out = tmp_path / "r.json"
    args = ["play", "--headless", "--arena", str(arena), "--bots", "6", "--seconds", "5",
            "--seed", "3", "--report", str(out)]
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, r.output
    assert "kills" in r.output and "steps/s" in r.output
    rep = json.loads(out.read_text())
    assert rep["arena"] == "testbox" and rep["seed"] == 3 and rep["seconds"] == 5.0
    assert len(rep["tanks"]) == 6
    for t in rep["tanks"]:
        assert {"name", "kills", "deaths", "shots", "hits", "wall_bumps", "distance", "position"} <= set(t)
        assert len(t["position"]) == 2
    assert set(rep["timing"]) == {"wall_clock_s", "steps_per_second", "realtime_factor", "prepare_s", "bots"}
    # each bot's time per call (machine-dependent, so under timing): calls over the budget counted
    assert {"calls", "over_budget", "mean_ms", "max_ms"} <= set(rep["timing"]["bots"]["bot1"])
    # same seed: same report apart from timing
    out2 = tmp_path / "r2.json"
    r = CliRunner().invoke(cli, args[:-1] + [str(out2)])
    assert r.exit_code == 0
    rep2 = json.loads(out2.read_text())
    rep.pop("timing"), rep2.pop("timing")
    assert rep == rep2


def test_play_without_headless_runs_a_match_and_writes_nothing_unasked(tmp_path, monkeypatch):
    # `make play` on a machine without a display used to leave match.png in the checkout
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    arena = _arena(tmp_path, maze=True)
    r = CliRunner().invoke(cli, ["play", "--arena", str(arena), "--seconds", "3"])
    assert r.exit_code == 0, r.output
    assert "no display to open the game window" in r.output
    assert "picture:" not in r.output
    assert list(work.iterdir()) == []
    assert sum(1 for line in r.output.splitlines() if line.startswith("bot")) == 4
    # asked for: the top view of the final state
    r = CliRunner().invoke(cli, ["play", "--arena", str(arena), "--seconds", "3", "--picture", "end.png"])
    assert r.exit_code == 0, r.output
    assert "picture: end.png" in r.output
    png = (work / "end.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_bad_input_is_one_line_and_exit_2(tmp_path):
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", str(tmp_path / "nowhere")])
    assert r.exit_code == 2
    assert "error:" in r.output and "nowhere" in r.output and "Traceback" not in r.output
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "walls.txt").write_text("0 0 10\n")
    (bad / "arena.toml").write_text('name = "bad"\nspawns = [[1, 1, 0]]\n')
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", str(bad)])
    assert r.exit_code == 2 and "walls.txt:1" in r.output
    arena = _arena(tmp_path)
    # more tanks than spawn points take free places; more than fit are refused in one line
    import numpy as np
    from tanktool.formats.walls_txt import WallList, aux_rectangle

    room = WallList(np.zeros((0, 2, 2)), np.zeros(0, np.int8), aux_rectangle(0, 0, 24, 24))
    small = write_arena_bundle(tmp_path / "small", room, np.array([[6.0, 6.0, 0.0], [18.0, 18.0, 3.1]]),
                               name="small")
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", str(small), "--bots", "12"])
    assert r.exit_code == 2 and "holds" in r.output and "(2 spawn points" in r.output, r.output
    assert len([ln for ln in r.output.splitlines() if ln.startswith("error:")]) == 1
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", str(arena), "--report",
                                 str(tmp_path / "no" / "such" / "r.json")])
    assert r.exit_code == 2 and "does not exist" in r.output
    assert not (tmp_path / "no").exists()


def test_reports_match_across_processes(tmp_path):
    """No hash-order or clock dependence: two interpreters with different hash seeds
    write the same report (apart from timing)."""
    import os
    import subprocess
    import sys

    arena = _arena(tmp_path, maze=True)
    reports = []
    for hashseed in ("1", "2"):
        out = tmp_path / f"r{hashseed}.json"
        env = dict(os.environ, PYTHONHASHSEED=hashseed)
        subprocess.run([sys.executable, "-m", "tanktool", "-q", "play", "--headless", "--arena", str(arena),
                        "--bots", "5", "--seconds", "4", "--seed", "9", "--report", str(out)],
                       check=True, env=env, capture_output=True)
        rep = json.loads(out.read_text())
        rep.pop("timing")
        reports.append(rep)
    assert reports[0] == reports[1]


def test_seconds_is_never_silently_ignored(tmp_path, monkeypatch):
    # a replay lasts as long as its recording: --seconds is refused with a word
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(cli, ["play", "--headless", "--arena", "box", "--bots", "2", "--seconds", "1",
                                 "--record", "m.ttr"])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["play", "--headless", "--replay", "m.ttr", "--seconds", "5"])
    assert r.exit_code == 0, r.output
    assert "warning: --seconds 5 ignored: a replay lasts as long as its recording" in r.output
    assert "120 steps" in r.output and "bit for bit" in r.output


def test_the_window_gets_one_match_config(tmp_path, monkeypatch):
    """``play`` builds one MatchConfig for the window: --bots counts your tank too, the
    limits become the match's rules, the recording and the view go in it whole."""
    import tanktool.game.app as app_mod

    seen = []
    monkeypatch.setattr(app_mod, "run_window", lambda config: seen.append(config) or [])
    rec = tmp_path / "m.ttr"
    r = CliRunner().invoke(cli, ["play", "--arena", "box", "--bots", "3", "--difficulty", "easy", "--seed", "7",
                                 "--time-limit", "30", "--score-limit", "5", "--record", str(rec),
                                 "--size", "800x600", "--view", "top", "--quality", "low"])
    assert r.exit_code == 0, r.output
    (cfg,) = seen
    assert (cfg.arena, cfg.seed, cfg.seconds) == ("box", 7, None)
    assert (cfg.opponents.count, cfg.opponents.difficulty, cfg.opponents.driver) == (2, "easy", "agent")
    assert (cfg.rules.time_limit, cfg.rules.score_limit) == (30.0, 5)
    assert (cfg.view.mode, cfg.view.size, cfg.view.quality) == ("top", (800, 600), "low")
    assert cfg.recording.record == rec and cfg.network is None
    assert "nothing recorded" in r.output


def test_help_and_readme_name_every_bundled_arena(root_dir):
    from tanktool.content import bundled_names

    r = CliRunner().invoke(cli, ["play", "--help"])
    readme = (root_dir / "README.md").read_text()
    names = bundled_names("arenas")
    assert len(names) >= 5
    for name in names:
        assert name in r.output, name
        assert f"| `arenas/{name}` |" in readme, name

