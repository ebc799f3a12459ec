"""The network message layout: round trips, strict validation, garbage never raises."""

from __future__ import annotations

import dataclasses

import math
import random
import struct
from collections import Counter

import pytest

from tanktool.net import protocol as P


def _table() -> P.Table:
    return P.Table(1, (P.Entry(1, 1, "127.0.0.1", 5000, 5000, "alice"),
                       P.Entry(3, 7, "10.0.0.2", 40001, 40002, "bób")))


BODIES = [
    P.Challenge(b"n" * 16, True),
    P.Join("carol", 41000, 41001, b"m" * 32),
    P.Hello(9, b"h" * 32),
    P.State(3, 12.5, 10.25, -4.5, 1.0, 2.0, -3.0, 0.5, 0.0, True),      # exact in f32 / f16 (hit points not sent)
    P.Shot(2, 1.0, 5.0, 6.0, -1.5, 0.25, 0.0),
    P.Hit(2, 3, 4.0, 25.0, 0.0, True, 7.0, 8.0),
    P.Exit(),
    P.Refuse(P.RefuseCode.FULL, "session full: 8 players"),
]


@pytest.mark.parametrize("body", BODIES, ids=lambda b: type(b).__name__)
def test_round_trip(body):
    sender = 0 if isinstance(body, (P.Join, P.Challenge, P.Refuse)) else 3
    data = P.encode(body, sender, 77, 1700000000.25)
    msg = P.decode(data)
    assert msg is not None
    assert msg.sender == sender and msg.seq == 77 and P.age(1700000000.25, msg.timestamp) == 0.0
    assert msg.body == (dataclasses.replace(body, hp=0.0) if isinstance(body, P.State) else body)
    assert data[:2] == P.MAGIC and len(data) == P.HEADER.size + struct.unpack("!H", data[13:15])[0]


@pytest.mark.parametrize("kind", [P.MessageType.NUMBER, P.MessageType.NEW_PLAYER])
def test_table_round_trip(kind):
    body = P.Assign(3, 42.0, _table())
    msg = P.decode(P.encode(body, 1, 1, 5.0, kind=kind))
    assert msg is not None and msg.type == kind
    assert msg.body == body
    assert msg.body.table.get(3).name == "bób" and msg.body.table.get(2) is None


def test_a_table_carries_the_hosts_probe_list():
    body = P.Assign(1, 7.0, _table(), 2, (("10.0.0.9", 5000), ("192.168.1.2", 40000)))
    raw = P.encode(body, 1, 1, 5.0, kind=P.MessageType.TABLE)
    assert P.decode(raw).body == body
    c = Counter()
    count_at = len(raw) - 1 - 2 * 6          # the count byte before the two addresses
    too_many = raw[:count_at] + bytes([P.MAX_PLAYERS + 1]) + raw[count_at + 1:]
    assert P.decode(too_many, c) is None and c["range"] == 1
    assert P.decode(raw[:count_at] + bytes([3]) + raw[count_at + 1:], c) is None and c["length"] == 1
    with pytest.raises(ValueError):
        P.encode(P.Assign(1, 7.0, _table(), 2, (("10.0.0.9", 5000),) * 9), 1, 1, 5.0, kind=P.MessageType.TABLE)


def test_state_is_small():
    # 30 Hz to 7 peers must stay under 16 KB/s up, even counting IPv4 + UDP headers
    n = len(P.encode(BODIES[3], 1, 1, 0.0))
    assert n == 36
    assert (n + 28) * 30 * 7 < 16 * 1024
    assert (n + 8 + 28) * 30 * 7 < 16 * 1024      # sealed (a password session) too


def test_state_precision():
    s = P.State(2, 3600.123, 55.123456, -7.654321, 3.14159, 13.7, -0.3, 1.234, 115.0, True)
    d = P.decode(P.encode(s, 2, 1, 0.0)).body
    # the heading as a half float: within 0.1 degree; hit points are not sent
    assert d.t == 3600.123 and abs(d.x - s.x) < 1e-5 and abs(d.heading - s.heading) < 2e-3
    assert abs(d.vx - s.vx) < 0.01 and abs(d.omega - s.omega) < 1e-3 and d.hp == 0.0 and d.alive
    dead = P.decode(P.encode(P.State(8, 1.0, 0, 0, 0, 0, 0, 0, 0, False), 2, 1, 0.0)).body
    assert dead.tank == 8 and not dead.alive
    # speeds beyond a half float's range are clamped when sent, not an error
    fast = P.State(2, 1.0, 0, 0, 0, 1e9, 0, 0, 115.0, True)
    assert P.decode(P.encode(fast, 2, 1, 0.0)).body.vx == P.MAX_SPEED


def test_header_fields_validated():
    good = P.encode(BODIES[3], 3, 1, 1.0)
    cases = {
        "magic": b"XX" + good[2:],
        "version": good[:2] + bytes([P.VERSION + 1]) + good[3:],
        "type": good[:3] + bytes([99]) + good[4:],
        "sender": good[:4] + bytes([9]) + good[5:],
        "length": good + b"\0",
        "short": good[:10],
    }
    for reason, data in cases.items():
        c = Counter()
        assert P.decode(data, c) is None, reason
        assert c[reason] == 1, (reason, c)
    # a numbered message with sender 0 is refused; a join may come from 0
    c = Counter()
    assert P.decode(P.encode(BODIES[3], 0, 1, 1.0), c) is None and c["sender"] == 1


def test_nan_and_ranges():
    c = Counter()
    nan_state = P.State(3, 1.0, math.nan, 0, 0, 0, 0, 0, 100, True)
    assert P.decode(P.encode(nan_state, 3, 1, 1.0), c) is None and c["nan"] == 1
    with pytest.raises(ValueError):             # the header's timestamp is a counter now
        P.encode(BODIES[3], 3, 1, math.inf)
    far = P.State(3, 1.0, 5e6, 0, 0, 0, 0, 0, 100, True)
    assert P.decode(P.encode(far, 3, 1, 1.0), c) is None and c["range"] == 1
    bad_tank = P.State(9, 1.0, 0, 0, 0, 0, 0, 0, 100, True)
    assert P.decode(P.encode(bad_tank, 3, 1, 1.0), c) is None and c["range"] == 2
    self_hit = P.Hit(3, 3, 1.0, 25.0, 0.0, False, 0, 0)
    assert P.decode(P.encode(self_hit, 3, 1, 1.0), c) is None and c["range"] == 3
    # a table whose host is not in it
    t = P.Table(5, (P.Entry(1, 1, "127.0.0.1", 1, 1, "a"),))
    assert P.decode(P.encode(P.Assign(1, 0.0, t), 1, 1, 1.0, kind=P.MessageType.NUMBER), c) is None
    # a bad name (control character) in a join
    raw = P.encode(P.Join("ab", 1, 1, b"m" * 32), 0, 1, 1.0)
    assert P.decode(raw[:-1] + b"\x07", c) is None and c["name"] == 1
    with pytest.raises(ValueError):
        P.encode(P.Join("x" * 25, 1, 1, b"m" * 32), 0, 1, 1.0)


def test_every_truncation_and_bitflip_is_handled():
    c = Counter()
    for body in BODIES:
        sender = 0 if isinstance(body, (P.Join, P.Challenge, P.Refuse)) else 3
        data = P.encode(body, sender, 5, 2.0)
        for cut in range(len(data)):
            assert P.decode(data[:cut], c) is None
        rng = random.Random(len(data))
        for _ in range(200):
            b = bytearray(data)
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
            msg = P.decode(bytes(b), c)      # may still be valid (e.g. a float bit): never raises
            if msg is not None:
                assert msg.type in set(P.MessageType)
    assert sum(c.values()) > 0


def test_random_garbage_never_raises():
    rng = random.Random(1)
    c = Counter()
    accepted = 0
    for _ in range(5000):
        n = rng.randrange(0, 120)
        data = bytes(rng.randrange(256) for _ in range(n))
        if rng.random() < 0.5:       # a valid header start makes the payload checks work
            data = P.MAGIC + bytes([P.VERSION, rng.randrange(1, 11)]) + data
        accepted += P.decode(data, c) is not None
    assert accepted == 0
    assert sum(c.values()) == 5000


def test_stream_reader_frames_and_breaks():
    c = Counter()
    r = P.StreamReader(c)
    data = b"".join(P.encode(b, 3, i, 1.0) for i, b in enumerate(BODIES[3:7]))
    got = []
    for i in range(0, len(data), 7):           # arbitrary TCP segmentation
        got += r.feed(data[i:i + 7])
    assert [m.body for m in got] == BODIES[3:7]
    # a well-framed message with a bad payload is dropped, the stream goes on
    bad = bytearray(P.encode(BODIES[3], 3, 9, 1.0))
    bad[P.HEADER.size] = 0                     # tank 0
    assert r.feed(bytes(bad) + P.encode(P.Exit(), 3, 10, 1.0))[0].body == P.Exit()
    assert c["range"] == 1 and not r.broken
    # a bad header breaks the stream for good
    assert r.feed(b"garbage" * 5) == [] and r.broken
    assert r.feed(P.encode(P.Exit(), 3, 11, 1.0)) == []
