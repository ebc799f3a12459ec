"""``tanktool play --host/--join``: one clear line and exit 2 for every network mistake,
and a short hosted match with its report."""

from __future__ import annotations

import json
import socket
import threading

import pytest
from click.testing import CliRunner

from net_helpers import match_kw

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


def _serving(password: str | None):
    """A host peer polled by a thread; returns (host, stop)."""
    host = Peer.host(("127.0.0.1", 0), "host", password, **match_kw("box"))
    done = threading.Event()

    def serve() -> None:
        while not done.is_set():
            host.poll(0.01)

    th = threading.Thread(target=serve, daemon=True)
    th.start()

    def stop() -> None:
        done.set()
        th.join(5)
        host.close()

    return host, stop


def test_refused_join_wrong_password():
    host, stop = _serving("pw")
    try:
        ip, port = host.tcp_address
        _one_line_error(_run("--join", f"{ip}:{port}", "--password", "nope", "--seconds", "1"), "wrong password")
        _one_line_error(_run("--join", f"{ip}:{port}", "--seconds", "1"), "wants a password")
    finally:
        stop()


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



def test_password_from_the_environment_or_a_prompt(tmp_path):
    host, stop = _serving("s3cret")
    try:
        ip, port = host.tcp_address
        where = f"{ip}:{port}"
        runner = CliRunner()
        args = ["play", "--headless", "--arena", "box", "--join", where, "--seconds", "0.5"]
        r = runner.invoke(cli, args, env={"TANKTOOL_PASSWORD": "s3cret"})
        assert r.exit_code == 0, r.output
        assert "joined" in r.output and "s3cret" not in r.output
        r = runner.invoke(cli, args, env={"TANKTOOL_PASSWORD": "wrong"})
        _one_line_error(r, "wrong password")
        # '-': typed at a prompt (here standard input, which is not a terminal)
        r = runner.invoke(cli, args + ["--password", "-"], input="s3cret\n", env={"TANKTOOL_PASSWORD": ""})
        assert r.exit_code == 0, r.output
        assert "s3cret" not in r.output
        r = runner.invoke(cli, args + ["--password", "-"], input="\n")
        assert r.exit_code == 2 and "no password given" in r.output
        # the command line still wins over the environment
        r = runner.invoke(cli, args + ["--password", "s3cret"], env={"TANKTOOL_PASSWORD": "wrong"})
        assert r.exit_code == 0, r.output
    finally:
        stop()
    assert host.dropped["refused_password"] == 1


def test_password_option_help_names_the_environment_variable():
    r = CliRunner().invoke(cli, ["play", "--help"], terminal_width=200)
    assert r.exit_code == 0 and "TANKTOOL_PASSWORD" in r.output and "'-'" in r.output


def test_attacks_logged_at_v_one_line_per_kind(tmp_path):
    """A host run with -v logs what it dropped: one line per kind with its count and
    where from, however many packets; without -v, nothing."""
    import os
    import subprocess
    import sys
    import time
    from collections import Counter
    from pathlib import Path

    from tanktool.net import protocol as P
    from tanktool.net.peer import free_port

    root = Path(__file__).resolve().parent.parent
    env = dict(os.environ, PYTHONPATH=str(root))
    results = {}
    for verbose in (True, False):
        port = free_port()
        cmd = [sys.executable, "-m", "tanktool", *(["-v"] if verbose else []), "play", "--headless", "--arena",
               "box", "--host", f"127.0.0.1:{port}", "--seconds", "4", "--report", str(tmp_path / "h.json")]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=root)
        try:
            deadline = time.monotonic() + 30
            line = ""
            while "hosting on" not in line and time.monotonic() < deadline:
                line = proc.stdout.readline()
            udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            good = P.encode(P.State(3, 1.0, 9, 9, 0, 0, 0, 0, 100, True), 3, 5, 1.0)
            for _ in range(200):
                udp.sendto(b"\xff" * 40, ("127.0.0.1", port))      # bad magic
                udp.sendto(good, ("127.0.0.1", port))             # nobody's number
            udp.close()
            silent = [socket.create_connection(("127.0.0.1", port), timeout=2) for _ in range(30)]
            out, err = proc.communicate(timeout=60)
            for s in silent:
                s.close()
        finally:
            if proc.poll() is None:
                proc.kill()
        assert proc.returncode == 0, err
        results[verbose] = err
    lines = [ln for ln in results[True].splitlines() if ln.startswith("network: ")]
    # the first drops are logged at once, the rest at most every 5 s (and at the end):
    # a line per kind each time, with the count since the last time
    counts: Counter = Counter()
    per_kind: Counter = Counter()
    for ln in lines:
        _, n, kind = ln.split()[:3]
        counts[kind.rstrip(":")] += int(n)
        per_kind[kind.rstrip(":")] += 1
        assert " from 127.0.0.1" in ln
    assert counts == {"magic": 200, "unknown": 200, "pending_timeout": 30}, lines
    assert max(per_kind.values()) <= 2 and len(lines) <= 6, lines
    assert "network: " not in results[False]
    rep = json.loads((tmp_path / "h.json").read_text())
    assert rep["network"]["dropped_reasons"]["magic"] == 200
