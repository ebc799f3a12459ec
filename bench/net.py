"""Network play on loopback: 8 peers as separate ``tanktool play`` processes.

Phase 1 (steady play): a host and 7 joiners join; one second after the last one, SIGUSR1
opens the measuring window (each peer restarts its traffic counters and latency samples);
they play for ``--seconds`` (the issue's goal run is 60 s; the default is 20 s to spare a
shared machine), then end with SIGINT and write their reports.  Per peer: state updates sent per second (rounds to every other peer),
updates received per second from each remote, state latency p50/p99 (receive time minus
the sender's timestamp; one clock, since all run on this machine), and bytes per second
up (message bytes, and with the 28 bytes of IPv4+UDP headers per datagram).

Phase 1 runs twice: a plain session, then a password session (TANKTOOL_PASSWORD), where
every datagram carries an 8-byte tag (keyed BLAKE2b) made with its link's key; the two
tables side by side show what authentication costs in latency and bytes.  Beside them,
in this process, the CPU of one state round: encoding it once (plain) against encoding
it and sealing it for 7 peers, and reading one datagram (decode) against checking its
tag first.

Phase 2 (migration): a fresh 8-peer session; the host is frozen with SIGSTOP (silent:
the others must wait out the 3 s silence), and this script joins through player 2 until
that works; then player 2, now host, is SIGKILLed (its links close at once) and the
script joins through player 3.  "Host kill to working new host" is the time from the
signal until a new player has its number from the new host.

Phase 3 (attack): a 3-peer password session; the time a new player takes to join, quiet
and then while an attacker holds 200 silent connections and opens ~500 more a second;
then a flood of joins with the password for 2 s: how many the host let in, and how many
of the host's messages the real peers dropped to their own rate limiters.

    python bench/net.py [--seconds S] [--peers N] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.errors import NetError  # noqa: E402
from tanktool.net import auth, probe  # noqa: E402
from tanktool.net import protocol as P  # noqa: E402
from tanktool.net.peer import Peer, free_port  # noqa: E402

LOOPBACK = "127.0.0.1"
IP_UDP_HEADERS = 28
PASSWORD = "bench s3cret"


class Proc:
    def __init__(self, args: list[str], password: str | None = None) -> None:
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        env.pop("TANKTOOL_PASSWORD", None)
        if password:
            env["TANKTOOL_PASSWORD"] = password
        self.p = subprocess.Popen([sys.executable, "-m", "tanktool", *args], stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL, text=True, env=env, cwd=ROOT)
        self.lines: list[str] = []
        self.t = threading.Thread(target=lambda: [self.lines.append(ln.rstrip()) for ln in self.p.stdout],
                                  daemon=True)
        self.t.start()

    def wait_line(self, pattern: str, timeout: float = 60.0) -> re.Match:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for line in list(self.lines):
                m = re.search(pattern, line)
                if m:
                    return m
            if self.p.poll() is not None:
                break
            time.sleep(0.02)
        raise RuntimeError(f"no line {pattern!r} from {self.p.args}: {self.lines}")

    def stop(self, sig: int = signal.SIGKILL) -> None:
        if self.p.poll() is None:
            try:
                self.p.send_signal(signal.SIGCONT)
                self.p.send_signal(sig)
            except ProcessLookupError:
                pass
        try:
            self.p.wait(30)
        except subprocess.TimeoutExpired:
            self.p.kill()
            self.p.wait(10)


def start_session(tmp: Path, peers: int, tag: str,
                  password: str | None = None) -> tuple[list[Proc], list[Path], dict[int, tuple[str, int]]]:
    """Host + joiners, everyone in; returns processes, report paths and player -> TCP address."""
    port = free_port(LOOPBACK)
    procs, reports = [], []
    for i in range(1, peers + 1):
        rep = tmp / f"{tag}{i}.json"
        role = ["--host", f"{LOOPBACK}:{port}"] if i == 1 else ["--join", f"{LOOPBACK}:{port}"]
        procs.append(Proc(["play", "--headless", "--arena", "box", "--seconds", "3600", "--seed", str(i),
                           "--name", f"{tag}{i}", "--report", str(rep), *role], password))
        reports.append(rep)
        if i == 1:
            procs[0].wait_line(r"hosting on")
    addresses = {1: (LOOPBACK, port)}
    for p in procs[1:]:
        m = p.wait_line(r"as player (\d) .*listening on ([\d.]+):(\d+)")
        addresses[int(m.group(1))] = (m.group(2), int(m.group(3)))
    for n in addresses:
        if n != 1:
            procs[0].wait_line(rf"player {n} \(.*\) joined")
    return procs, reports, addresses


def join_until_working(address: tuple[str, int], since: float, timeout: float = 15.0,
                       password: str | None = None) -> tuple[float, int]:
    """Seconds from ``since`` until a join through ``address`` gets a number, and the host."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            p = Peer.join(address, "newcomer", password, timeout=1.0)
        except NetError as e:
            if os.environ.get("BENCH_NET_DEBUG"):
                print(f"  {time.monotonic() - since:.3f} s: {e}", file=sys.stderr)
            time.sleep(0.01)
            continue
        took = time.monotonic() - since
        host = p.host_number
        p.close()
        return took, host
    raise RuntimeError(f"no working host at {address} after {timeout} s")


def steady(tmp: Path, peers: int, seconds: float, password: str | None = None) -> list[dict]:
    procs, reports, _ = start_session(tmp, peers, "auth" if password else "steady", password)
    try:
        time.sleep(1.0)                 # let the last joiner settle, then open the window
        for p in procs:
            p.p.send_signal(signal.SIGUSR1)
        time.sleep(seconds)
        for p in procs:                 # SIGINT: each ends cleanly and writes its report
            p.p.send_signal(signal.SIGINT)
        for p in procs:
            p.stop(signal.SIGINT)
        return [json.loads(r.read_text()) for r in reports]
    finally:
        for p in procs:
            p.stop()


def migration(tmp: Path, peers: int) -> dict:
    procs, _, addr = start_session(tmp, peers, "mig")
    by_number = {1: procs[0]}
    for p in procs[1:]:
        by_number[int(p.wait_line(r"as player (\d)").group(1))] = p
    try:
        time.sleep(2.0)
        by_number[1].p.send_signal(signal.SIGSTOP)          # frozen: silent, its links stay open
        t0 = time.monotonic()
        silent_s, host_a = join_until_working(addr[2], t0)
        time.sleep(1.0)
        by_number[2].p.send_signal(signal.SIGKILL)          # gone: its links close at once
        t1 = time.monotonic()
        killed_s, host_b = join_until_working(addr[3], t1)
        return {"silent_host_s": round(silent_s, 3), "host_after_silence": host_a,
                "killed_host_s": round(killed_s, 3), "host_after_kill": host_b}
    finally:
        for p in procs:
            p.stop()


def seal_costs(rounds: int = 20000) -> dict:
    """Microseconds per state round and per datagram read, plain against sealed (this
    process, one core): the CPU that authentication adds to each."""
    key = auth.datagram_key(PASSWORD, bytes(32))
    keys = [auth.datagram_key(PASSWORD, bytes([k]) * 32) for k in range(7)]
    state = P.State(2, 12.5, 10.25, -4.5, 1.0, 2.0, -3.0, 0.5, 90.0, True)

    def per_op(fn) -> float:
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            for k in range(rounds):
                fn(k)
            best = min(best, (time.perf_counter() - t0) / rounds * 1e6)
        return round(best, 2)

    plain_send = per_op(lambda k: P.encode(state, 2, k, 1.0))
    sealed_send = per_op(lambda k: [auth.seal(kk, d) for d in (P.encode(state, 2, k, 1.0),) for kk in keys])
    datagram = P.encode(state, 2, 7, 1.0)
    sealed = auth.seal(key, datagram)
    plain_read = per_op(lambda k: P.decode(datagram))
    sealed_read = per_op(lambda k: P.decode(auth.unseal(key, sealed)))
    return {"send_round_plain_us": plain_send, "send_round_sealed_7_us": sealed_send,
            "read_plain_us": plain_read, "read_sealed_us": sealed_read,
            "datagram_bytes_plain": len(datagram), "datagram_bytes_sealed": len(sealed)}


def attack(tmp: Path) -> dict:
    procs, reports, _ = start_session(tmp, 3, "atk", PASSWORD)
    address = (LOOPBACK, int(procs[0].wait_line(r"hosting on [\d.]+:(\d+)").group(1)))
    try:
        time.sleep(1.0)
        t0 = time.monotonic()
        quiet_s, _ = join_until_working(address, t0, password=PASSWORD)
        stop = threading.Event()
        th = threading.Thread(target=probe.silent_flood, args=(address, stop), daemon=True)
        th.start()
        time.sleep(1.0)                 # the attacker's connections fill the pending list
        t1 = time.monotonic()
        try:
            attacked_s, _ = join_until_working(address, t1, password=PASSWORD)
        finally:
            stop.set()
            th.join(10)
        replies: Counter = Counter()
        end = time.monotonic() + 2.0
        while time.monotonic() < end:
            replies[probe.join_once(address, PASSWORD)] += 1
        time.sleep(1.0)
        for p in procs:
            p.p.send_signal(signal.SIGINT)
        for p in procs:
            p.stop(signal.SIGINT)
        reps = [json.loads(r.read_text()) for r in reports]
    finally:
        for p in procs:
            p.stop()
    host = next(r for r in reps if r["me"] == 1)
    return {"join_quiet_s": round(quiet_s, 3), "join_under_silent_flood_s": round(attacked_s, 3),
            "flood_joins": sum(replies.values()), "flood_admitted": replies["NUMBER"],
            "flood_refused": sum(n for r, n in replies.items() if r.startswith("REFUSE")),
            "host_evicted": host["network"]["dropped_reasons"].get("evicted", 0),
            "peers_rate_drops": [r["network"]["dropped_reasons"].get("rate", 0) for r in reps if r["me"] != 1]}


def rows_of(reports: list[dict], peers: int) -> list[dict]:
    rows = []
    for r in sorted(reports, key=lambda r: r["me"]):
        s = r["stats_seconds"]
        net = r["network"]
        others = max(peers - 1, 1)
        rows.append({
            "peer": r["me"], "seconds": s,
            "updates_per_s": round(net["state_rounds"] / s, 1),
            "received_per_s_per_remote": round(net["states_received"] / s / others, 1),
            "latency_p50_ms": r["latency_ms"]["p50"], "latency_p99_ms": r["latency_ms"]["p99"],
            "bytes_up_per_s": round(net["bytes_sent"] / s),
            "bytes_up_per_s_with_headers": round((net["bytes_sent"] + IP_UDP_HEADERS * net["states_sent"]) / s),
            "dropped": net["dropped"],
        })
    return rows


def worst_of(rows: list[dict]) -> dict:
    return {
        "min_updates_per_s": min(r["updates_per_s"] for r in rows),
        "median_latency_p50_ms": sorted(r["latency_p50_ms"] for r in rows)[len(rows) // 2],
        "max_latency_p99_ms": max(r["latency_p99_ms"] for r in rows),
        "max_bytes_up_per_s": max(r["bytes_up_per_s"] for r in rows),
        "max_bytes_up_per_s_with_headers": max(r["bytes_up_per_s_with_headers"] for r in rows),
    }


def print_table(title: str, rows: list[dict], worst: dict) -> None:
    print(title)
    head = (f"{'peer':>4} {'upd/s':>6} {'recv/s/remote':>13} {'p50 ms':>7} {'p99 ms':>7} "
            f"{'B/s up':>7} {'+hdrs':>7} {'dropped':>7}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['peer']:>4} {r['updates_per_s']:>6.1f} {r['received_per_s_per_remote']:>13.1f} "
              f"{r['latency_p50_ms']:>7.3f} {r['latency_p99_ms']:>7.3f} {r['bytes_up_per_s']:>7} "
              f"{r['bytes_up_per_s_with_headers']:>7} {r['dropped']:>7}")
    print(f"worst: {worst['min_updates_per_s']} updates/s (goal 30), p99 {worst['max_latency_p99_ms']} ms "
          f"(goal < 10), {worst['max_bytes_up_per_s']} B/s up (goal < 16384)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=20.0, help="steady play (the issue's goal run: 60)")
    ap.add_argument("--peers", type=int, default=8)
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    args = ap.parse_args()
    costs = seal_costs()
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        # the machine may be shared: say how busy it was when each phase began
        load_plain = round(os.getloadavg()[0], 2)
        plain = rows_of(steady(tmp, args.peers, args.seconds), args.peers)
        load_sealed = round(os.getloadavg()[0], 2)
        sealed = rows_of(steady(tmp, args.peers, args.seconds, PASSWORD), args.peers)
        mig = migration(tmp, args.peers)
        atk = attack(tmp)
    worst, worst_sealed = worst_of(plain), worst_of(sealed)
    result = {"peers": args.peers, "seconds": args.seconds, "rows": plain, "worst": worst, "load_average": load_plain,
              "password": {"rows": sealed, "worst": worst_sealed, "load_average": load_sealed},
              "seal_costs": costs, "migration": mig,
              "attack": atk,
              "goals": {"updates_per_s": 30, "latency_p99_ms": 10, "bytes_up_per_s": 16 * 1024, "migration_s": 3}}
    if args.json:
        print(json.dumps(result))
        return
    print_table(f"{args.peers} peers on loopback, {args.seconds:g} s of steady play (separate processes, box arena; "
                f"load average {load_plain} at the start)", plain, worst)
    print()
    print_table("the same with a password: every datagram sealed (keyed BLAKE2b, 8-byte tag, a key per pair; "
                f"load average {load_sealed})", sealed, worst_sealed)
    print()
    print(f"{'':<34} {'plain':>9} {'password':>9}")
    print(f"{'median p50 state latency [ms]':<34} {worst['median_latency_p50_ms']:>9.3f} "
          f"{worst_sealed['median_latency_p50_ms']:>9.3f}")
    print(f"{'worst p99 state latency [ms]':<34} {worst['max_latency_p99_ms']:>9.3f} "
          f"{worst_sealed['max_latency_p99_ms']:>9.3f}")
    print(f"{'worst B/s up (+ IPv4/UDP headers)':<34} {worst['max_bytes_up_per_s']:>9} "
          f"{worst_sealed['max_bytes_up_per_s']:>9}   ({worst['max_bytes_up_per_s_with_headers']} / "
          f"{worst_sealed['max_bytes_up_per_s_with_headers']})")
    print(f"{'state datagram [bytes]':<34} {costs['datagram_bytes_plain']:>9} {costs['datagram_bytes_sealed']:>9}")
    print(f"{'one state round, 7 peers [us CPU]':<34} {costs['send_round_plain_us']:>9.2f} "
          f"{costs['send_round_sealed_7_us']:>9.2f}")
    print(f"{'reading one datagram [us CPU]':<34} {costs['read_plain_us']:>9.2f} {costs['read_sealed_us']:>9.2f}")
    print()
    print(f"migration: host frozen (SIGSTOP) -> join through player {mig['host_after_silence']} works after "
          f"{mig['silent_host_s']} s; host SIGKILLed -> join through player {mig['host_after_kill']} works after "
          f"{mig['killed_host_s']} s (goal < 3 s)")
    print(f"attack (password session of 3): a join takes {atk['join_quiet_s']} s quiet, "
          f"{atk['join_under_silent_flood_s']} s while 200 silent connections are held and ~500/s more opened "
          f"({atk['host_evicted']} evicted); a 2 s flood of {atk['flood_joins']} joins: {atk['flood_admitted']} "
          f"admitted, {atk['flood_refused']} refused; the real peers' rate-limit drops: {atk['peers_rate_drops']}")


if __name__ == "__main__":
    main()
