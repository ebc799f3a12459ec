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

Phase 4 (judge, in this process): the CPU a member state costs the host, decoded and
kept for drawing, with the judge's checks (net/judge.py) and without them, on a flat
arena (box) and a ground (hills); and the same through the host's protocol core
(net/core.py), the whole path a datagram takes after the socket.

Phase 5 (flood): a host and an honest joiner as processes; this script joins as a third
member and floods the host with 20,000 valid states a second from its own address for
``--flood-seconds``; the host's report says how many of the honest player's states it
took a second (goal: the 30 it sends), how many flood datagrams it dropped unread, and
how many steps it had to skip.

    python bench/net.py [--seconds S] [--peers N] [--parts steady,password,migration,attack,judge,flood] [--json]
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


def box_digest() -> bytes:
    """The match digest of the sessions started here (box, its default vehicle): a
    joiner on anything else is refused."""
    from tanktool.net.digest import match_digest
    from tanktool.sim.match import choose_vehicle, load_match_arena, load_tank_spec

    info = load_match_arena("box")
    return match_digest(info, load_tank_spec(choose_vehicle(info, None, lambda line: None)))


def join_until_working(address: tuple[str, int], since: float, timeout: float = 15.0,
                       password: str | None = None) -> tuple[float, int]:
    """Seconds from ``since`` until a join through ``address`` gets a number, and the host."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            p = Peer.join(address, "newcomer", password, timeout=1.0, digest=box_digest())
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


def judge_costs(states: int = 1500) -> dict:
    """Microseconds of host CPU per member state (decode, then kept for drawing), with
    the judge and without, on box (flat) and hills (a ground): an honest tank circling."""
    import math
    import random

    from tanktool.net.judge import Judge
    from tanktool.net.remote import RemoteTank
    from tanktool.net.session import NET_RULES
    from tanktool.sim.driver import ScriptedDriver
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.world import World

    out = {}
    spec = load_tank_spec("light")
    for arena in ("box", "hills"):
        info = load_match_arena(arena)
        world = World(info.walls, [spec] * 8, info.spawns, bounds=info.bounds, ground=info.ground, rules=NET_RULES)
        # an honest stream: tank 2 of a scripted match, sampled at 30 Hz
        sim = World(info.walls, [spec] * 2, info.spawns, seed=5, bounds=info.bounds, ground=info.ground,
                    rules=NET_RULES)
        drivers = [ScriptedDriver(random.Random(k)) for k in range(2)]
        msgs, next_t = [], 0.0
        while len(msgs) < states:
            sim.step(None, [d(sim, t) if t.alive else None for d, t in zip(drivers, sim.tanks)])
            if sim.t >= next_t:
                next_t += 1.0 / 30.0
                t = sim.tanks[1]
                msgs.append(P.encode(P.State(2, sim.t, t.x, t.z, math.remainder(t.heading, 2 * math.pi), t.vx, t.vz,
                                             t.omega, t.hp, t.alive), 2, len(msgs) + 1, sim.t))

        def run(judged: bool) -> float:
            best = float("inf")
            for _ in range(3):
                judge, rt = Judge(world), RemoteTank()
                t0 = time.perf_counter()
                for d in msgs:
                    m = P.decode(d)
                    shown = judge.state(m.body, m.body.t) if judged else m.body
                    if shown is not None:
                        rt.push(shown)
                best = min(best, (time.perf_counter() - t0) / len(msgs) * 1e6)
            corrected = sum(judge.corrections.values()) if judged else 0
            assert corrected == 0, judge.report()
            return best

        def through_core(judged: bool) -> float:
            """The whole path of a member's datagram in the host's protocol core (budget,
            member check, window, rate, judge, event), no socket."""
            from tanktool.net.core import Core

            best = float("inf")
            for _ in range(3):
                core, rt = Core("host"), RemoteTank()
                core.start_host((LOOPBACK, 5000, 5000), 0.0)
                core.table[2] = P.Entry(2, 2, LOOPBACK, 5002, 5002, "member")
                core.window.anchor(2, 0, 0.0)
                core.judge = Judge(world) if judged else None
                stamps = [P.decode(d).timestamp for d in msgs]
                t0 = time.perf_counter()
                for d, now in zip(msgs, stamps):
                    core.datagram((LOOPBACK, 5002), d, now)
                    for ev in core.take_events():
                        rt.push(ev.body)
                best = min(best, (time.perf_counter() - t0) / len(msgs) * 1e6)
                assert core.counters["states_received"] == len(msgs), core.network_report()
                assert not judged or not core.judge.corrections, core.judge.report()
            return best

        off, on = run(False), run(True)
        core_off, core_on = through_core(False), through_core(True)
        out[arena] = {"off_us": round(off, 2), "on_us": round(on, 2), "ratio": round(on / off, 2),
                      "core_off_us": round(core_off, 2), "core_on_us": round(core_on, 2),
                      "core_ratio": round(core_on / core_off, 2)}
    return out


def flood(tmp: Path, seconds: float, rate: float = 20000.0) -> dict:
    """A host and an honest member (processes); this process joins and floods the host
    with ``rate`` valid states a second from its own address."""
    from tanktool.net.digest import match_digest
    from tanktool.sim.match import choose_vehicle, load_match_arena, load_tank_spec

    info = load_match_arena("box")
    spec = load_tank_spec(choose_vehicle(info, None, lambda line: None))
    port = free_port(LOOPBACK)
    rep_h, rep_o = tmp / "flood_host.json", tmp / "flood_honest.json"
    base = ["play", "--headless", "--arena", "box", "--seconds", "3600"]
    host = Proc([*base, "--name", "fhost", "--report", str(rep_h), "--host", f"{LOOPBACK}:{port}"])
    procs = [host]
    try:
        host.wait_line(r"hosting on")
        honest = Proc([*base, "--name", "honest", "--report", str(rep_o), "--join", f"{LOOPBACK}:{port}"])
        procs.append(honest)
        n_honest = int(honest.wait_line(r"as player (\d)").group(1))
        flooder = Peer.join((LOOPBACK, port), "flooder", digest=match_digest(info, spec))
        try:
            time.sleep(1.0)
            for p in procs:
                p.p.send_signal(signal.SIGUSR1)
            t0 = time.monotonic()
            sent, next_poll = 0, t0
            target = (LOOPBACK, port)
            while True:
                now = time.monotonic()
                if now - t0 >= seconds:
                    break
                if now >= next_poll:
                    flooder.poll(0)
                    next_poll = now + 0.01
                due = int((now - t0) * rate) - sent
                if due <= 0:
                    time.sleep(0.0005)
                    continue
                st = P.State(flooder.number, flooder.session_time(), 20.0, 20.0, 0.0, 0.0, 0.0, 0.0, 100.0, True)
                for _ in range(min(due, 500)):
                    flooder.udp.sendto(flooder._pack(st), target)
                sent += min(due, 500)
            flood_s = time.monotonic() - t0
        finally:
            flooder.close()
        for p in procs:
            p.p.send_signal(signal.SIGINT)
        for p in procs:
            p.stop(signal.SIGINT)
        h, o = json.loads(rep_h.read_text()), json.loads(rep_o.read_text())
    finally:
        for p in procs:
            p.stop()
    s = h["stats_seconds"]
    net = h["network"]
    return {"flood_per_s": round(sent / flood_s), "seconds": round(s, 2),
            "honest_sent_per_s": round(o["network"]["state_rounds"] / o["stats_seconds"], 1),
            "honest_taken_by_host_per_s": round(net["states_received_by_sender"].get(str(n_honest), 0) / s, 1),
            "flood_dropped_unread": net["dropped_reasons"].get("flood", 0),
            "host_skipped_steps": h["timing"]["skipped_steps"]}


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


PARTS = ("steady", "password", "migration", "attack", "judge", "flood")


def measure(args: argparse.Namespace, parts: set[str]) -> dict:
    """Run the phases named in ``parts``; one dict of every figure (the --json object)."""
    result: dict = {"peers": args.peers, "seconds": args.seconds,
                    "goals": {"updates_per_s": 30, "latency_p99_ms": 10, "bytes_up_per_s_with_headers": 16 * 1024,
                              "migration_s": 3, "honest_per_s_under_flood": 30}}
    result["seal_costs"] = seal_costs()
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        # the machine may be shared: say how busy it was when each phase began
        if "steady" in parts:
            load = round(os.getloadavg()[0], 2)
            rows = rows_of(steady(tmp, args.peers, args.seconds), args.peers)
            result.update(rows=rows, worst=worst_of(rows), load_average=load)
        if "password" in parts:
            load = round(os.getloadavg()[0], 2)
            rows = rows_of(steady(tmp, args.peers, args.seconds, PASSWORD), args.peers)
            result["password"] = {"rows": rows, "worst": worst_of(rows), "load_average": load}
        if "migration" in parts:
            result["migration"] = migration(tmp, args.peers)
        if "attack" in parts:
            result["attack"] = attack(tmp)
        if "judge" in parts:
            result["judge"] = judge_costs()
        if "flood" in parts:
            result["flood"] = dict(flood(tmp, args.flood_seconds), load_average=round(os.getloadavg()[0], 2))
    return result


def print_judge_and_flood(result: dict) -> None:
    if "judge" in result:
        print("host CPU per member state, in this process [us]: decode + kept for drawing; and the whole path")
        print("through the protocol core (net/core.py: budget, member, window, rate, judge, event)")
        print(f"{'arena':<8} {'no judge':>9} {'judged':>9} {'ratio':>6} {'core, no judge':>15} {'judged':>9} {'ratio':>6}")
        for arena, c in result["judge"].items():
            print(f"{arena:<8} {c['off_us']:>9.2f} {c['on_us']:>9.2f} {c['ratio']:>6.2f} {c['core_off_us']:>15.2f} "
                  f"{c['core_on_us']:>9.2f} {c['core_ratio']:>6.2f}")
        print()
    if "flood" in result:
        f = result["flood"]
        print(f"flood: a member sends {f['flood_per_s']} valid states/s for {f['seconds']} s; the honest member "
              f"sends {f['honest_sent_per_s']}/s and the host takes {f['honest_taken_by_host_per_s']}/s of them "
              f"(goal 30); {f['flood_dropped_unread']} flood datagrams dropped unread, "
              f"{f['host_skipped_steps']} host steps skipped (load average {f['load_average']})")
        print()


def print_steady(result: dict) -> None:
    """The plain and sealed tables, their comparison, then migration and attack if run."""
    peers, seconds, costs = result["peers"], result["seconds"], result["seal_costs"]
    plain, worst, load_plain = result["rows"], result["worst"], result["load_average"]
    sealed, worst_sealed, load_sealed = (result["password"][k] for k in ("rows", "worst", "load_average"))
    mig, atk = result.get("migration"), result.get("attack")
    print_table(f"{peers} peers on loopback, {seconds:g} s of steady play (separate processes, box arena; "
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
    if mig is None or atk is None:
        return
    print()
    print(f"migration: host frozen (SIGSTOP) -> join through player {mig['host_after_silence']} works after "
          f"{mig['silent_host_s']} s; host SIGKILLed -> join through player {mig['host_after_kill']} works after "
          f"{mig['killed_host_s']} s (goal < 3 s)")
    print(f"attack (password session of 3): a join takes {atk['join_quiet_s']} s quiet, "
          f"{atk['join_under_silent_flood_s']} s while 200 silent connections are held and ~500/s more opened "
          f"({atk['host_evicted']} evicted); a 2 s flood of {atk['flood_joins']} joins: {atk['flood_admitted']} "
          f"admitted, {atk['flood_refused']} refused; the real peers' rate-limit drops: {atk['peers_rate_drops']}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=20.0, help="steady play (the issue's goal run: 60)")
    ap.add_argument("--peers", type=int, default=8)
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--parts", default=",".join(PARTS), help="which phases to run (comma-separated)")
    ap.add_argument("--flood-seconds", type=float, default=5.0)
    args = ap.parse_args()
    parts = set(args.parts.split(","))
    unknown = parts - set(PARTS)
    if unknown:
        ap.error(f"--parts: unknown {sorted(unknown)}")
    result = measure(args, parts)
    if args.json:
        print(json.dumps(result))
        return
    print_judge_and_flood(result)
    if {"steady", "password"} <= parts:
        print_steady(result)


if __name__ == "__main__":
    main()
