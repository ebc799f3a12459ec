"""``tanktool play --host/--join``: one clear line and exit 2 for every network mistake,
and a short hosted match with its report."""

from __future__ import annotations

import json
import socket
import threading

import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.net.peer import Peer


def _run(*args: str):
    return CliRunner().invoke(cli, ["play", "--headless", "--arena", "box", *args])


def _one_line_error(r, text: str) -> None:
    assert r.exit_code == 2, r.output
    assert text in r.output and "Traceback" not in r.output
    assert len([ln for ln in r.output.splitlines() if ln.strip()]) == 1


@pytest.mark.parametrize("addr", ["nonsense", "1.2.3:80", "127.0.0.1:70000", "host.example:80"])
def test_bad_join_address(addr):
    _one_line_error(_run("--join", addr), "error:")


def test_host_and_join_together():
    r = _run("--host", "5000", "--join", "127.0.0.1:5000")
    assert r.exit_code == 2 and "exclude" in r.output


def test_port_in_use_and_nobody_there():
    busy = socket.socket()
    busy.bind(("127.0.0.1", 0))
    busy.listen(1)
    try:
        port = busy.getsockname()[1]
        _one_line_error(_run("--host", f"127.0.0.1:{port}", "--seconds", "1"), "in use")
    finally:
        busy.close()
    _one_line_error(_run("--join", f"127.0.0.1:{port}", "--seconds", "1"), "cannot reach")


def test_refused_join_wrong_password():
    host = Peer.host(("127.0.0.1", 0), "host", "pw")
    done = threading.Event()

    def serve() -> None:
        while not done.is_set():
            host.poll(0.01)

    th = threading.Thread(target=serve, daemon=True)
    th.start()
    try:
        ip, port = host.tcp_address
        _one_line_error(_run("--join", f"{ip}:{port}", "--password", "nope", "--seconds", "1"), "wrong password")
        _one_line_error(_run("--join", f"{ip}:{port}", "--seconds", "1"), "wants a password")
    finally:
        done.set()
        th.join(5)
        host.close()


def test_hosted_match_report(tmp_path):
    out = tmp_path / "host.json"
    r = _run("--host", "127.0.0.1:0", "--seconds", "1.5", "--name", "solo", "--report", str(out))
    assert r.exit_code == 0, r.output
    assert "hosting on 127.0.0.1:" in r.output
    rep = json.loads(out.read_text())
    assert rep["me"] == 1 and rep["host"] == 1 and rep["host_changes"] == []
    assert rep["peers"] == [dict(rep["peers"][0], number=1, name="solo")]
    assert set(rep["network"]) >= {"sent", "received", "dropped"}
    assert 1.0 <= rep["session_time"] <= 3.0 and len(rep["views"]) >= 1


def test_bots_only_on_the_host():
    r = _run("--join", "127.0.0.1:5000", "--bots", "2")
    assert r.exit_code == 2 and "--bots goes with --host" in r.output
    r = _run("--host", "127.0.0.1:0", "--bots", "8")
    assert r.exit_code == 2 and "at most 7 bots" in r.output


def test_hosted_match_with_bots(tmp_path):
    out = tmp_path / "bots.json"
    r = _run("--host", "127.0.0.1:0", "--bots", "3", "--seconds", "1.5", "--report", str(out))
    assert r.exit_code == 0, r.output
    rep = json.loads(out.read_text())
    assert [(p["number"], p["bot"], p["run_by"]) for p in rep["peers"]] == [(1, False, 1), (2, True, 1),
                                                                             (3, True, 1), (4, True, 1)]
    moved = [p for p in rep["peers"] if p["bot"]]
    assert len({tuple(p["position"]) for p in moved}) == 3      # three tanks in three places
