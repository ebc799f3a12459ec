"""tanktool tournament on Ray: one local cluster for this module (ray.init with two
CPUs), the same report as serial, the bot written from docs/bots.md played on it,
and a bot file the workers cannot read played from the source sent with the task."""

from __future__ import annotations

import json
import shutil
import signal
from pathlib import Path

import pytest
from click.testing import CliRunner

ray = pytest.importorskip("ray")

from tanktool.cli.main import cli  # noqa: E402
from tanktool.tournament import TournamentConfig, resolve_players, run_tournament, schedule  # noqa: E402
from tanktool.tournament.runners import run_ray  # noqa: E402

HERE = Path(__file__).resolve().parent
HUNTER = str(HERE / "data" / "bots" / "hunter.py") + ":Hunter"


@pytest.fixture(scope="module")
def cluster():
    # ray.init installs a SIGTERM handler that does not exit; left in place it is
    # inherited by every process this pytest worker forks later, and Pool.terminate
    # then waits for ever on a worker blocked on its task queue (a hung CI run:
    # test_tiles' pool after this module on the same xdist worker)
    handlers = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGINT)}
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    if started:
        ray.shutdown()
    for sig, handler in handlers.items():
        signal.signal(sig, handler)


def _plain(report: dict) -> dict:
    return {k: v for k, v in report.items() if k != "timing"}


def test_ray_gives_the_serial_report_with_the_docs_bot(cluster):
    config = TournamentConfig(bots=("novice", HUNTER, "robot"), matches=2, seconds=12.0, boot=50)
    on_ray = run_tournament(config, run="ray", workers=2)
    serial = run_tournament(config, run="serial")
    assert on_ray.report["timing"]["runner"] == "ray"
    assert _plain(on_ray.report) == _plain(serial.report)
    assert on_ray.replays == serial.replays


def test_the_cli_on_ray(cluster, tmp_path):
    out = tmp_path / "t.json"
    args = ["tournament", "--bot", HUNTER, "--bot", "easy", "--matches", "2", "--seconds", "8", "--boot", "20"]
    r = CliRunner().invoke(cli, args + ["--json", str(out), "--ray", "local", "--workers", "2"])
    assert r.exit_code == 0, r.output
    on_ray = json.loads(out.read_text())
    assert on_ray["timing"]["runner"] == "ray"
    r = CliRunner().invoke(cli, args + ["--json", str(tmp_path / "s.json"), "--workers", "1"])
    assert r.exit_code == 0, r.output
    assert _plain(json.loads((tmp_path / "s.json").read_text())) == _plain(on_ray)
    for a, b in zip(sorted((tmp_path / "t-replays").iterdir()), sorted((tmp_path / "s-replays").iterdir())):
        assert a.read_bytes() == b.read_bytes()


def test_a_bot_file_the_workers_lack_is_sent_with_the_task(cluster, tmp_path):
    copy = tmp_path / "elsewhere" / "hunter_copy.py"
    copy.parent.mkdir()
    shutil.copy(HERE / "data" / "bots" / "hunter.py", copy)
    config = TournamentConfig(bots=(f"{copy}:Hunter", "novice"), matches=1, seconds=4.0)
    tasks = schedule(config, resolve_players(config.bots), record=False)
    shutil.rmtree(copy.parent)                       # as on a machine that never had it
    results = list(run_ray(tasks, 2))
    assert len(results) == 1 and results[0]["a"] == "Hunter" and "bot_errors" not in results[0]


def test_the_cli_joins_a_running_cluster_by_its_address(cluster, tmp_path):
    import subprocess
    import sys

    address = cluster.get_runtime_context().gcs_address
    out = tmp_path / "t.json"
    r = subprocess.run([sys.executable, "-m", "tanktool.cli.main", "tournament", "--bot", HUNTER, "--bot", "novice",
                        "--matches", "2", "--seconds", "4", "--json", str(out), "--no-replays", "--ray", address],
                       capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stderr[-2000:]
    report = json.loads(out.read_text())
    assert report["timing"]["runner"] == "ray" and len(report["matches"]) == 2
    serial = run_tournament(TournamentConfig(bots=(HUNTER, "novice"), matches=2, seconds=4.0), run="serial",
                            record=False)
    assert _plain(serial.report) == _plain(report)
