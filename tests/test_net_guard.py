"""The pieces that keep a session up under attack (net/guard.py) and the datagram
tags (net/auth.py), on their own: clocks passed in, no sockets."""

from __future__ import annotations

import random

from tanktool.net import auth
from tanktool.net import protocol as P
from tanktool.net.guard import Bucket, Buckets, DropLog, SeqWindow


def test_bucket_rate_and_burst():
    b = Bucket(10.0, 3.0, now=0.0)
    assert [b.take(0.0) for _ in range(4)] == [True, True, True, False]
    assert b.take(0.1) and not b.take(0.1)          # 10 a second: one more after 0.1 s
    assert not b.full(0.1) and b.full(1.0)


def test_buckets_are_bounded_and_forgotten_when_full():
    bs = Buckets(1.0, 2.0, max_keys=3)
    for ip in "abc":
        assert bs.take(ip, 0.0)
    assert not bs.take("d", 0.0)                    # all three still busy: the newest waits
    assert bs.take("d", 5.0)                        # a, b, c refilled: forgotten, room again
    assert set(bs.buckets) == {"d"}
    assert bs.has_token("d", 5.0) and bs.take("d", 5.0) and not bs.has_token("d", 5.0)


def test_sequence_window():
    w = SeqWindow(slack=10, rate=100.0)
    assert w.admits(2, 5, 0.0) is None              # no anchor: nothing is admitted
    w.anchor(2, 1000, 0.0)
    assert w.admits(2, 1010, 0.0) and not w.admits(2, 1011, 0.0)
    assert w.admits(2, 1110, 1.0) and not w.admits(2, 1111, 1.0)     # the window grows with time
    assert not w.admits(2, 10**9, 3600.0)           # but never to a far-future number
    w.anchor(2, 900, 2.0)                           # an older number does not move the anchor
    assert w.anchors[2] == (1000, 0.0)
    w.forget(2)
    assert w.admits(2, 1000, 0.0) is None


def test_drop_log_lines_one_per_kind_with_sources():
    d = DropLog()
    for k in range(500):
        d.source = ("10.0.0.9", 4000)
        d["bad_mac"] += 1
        d.source = f"10.0.0.{k % 7}"
        d["evicted"] += 1
    d.source = None
    d["stale"] += 2
    lines = d.lines(5.0)
    assert len(lines) == 3 and not d.grown
    assert lines[0].startswith("network: 500 bad_mac in the last 5 s: datagrams with a missing or wrong MAC; "
                               "from 10.0.0.9:4000 (500)")
    assert lines[1].startswith("network: 500 evicted in the last 5 s") and "and 4 more" in lines[1]
    assert lines[2] == "network: 2 stale in the last 5 s: stale states (an older sequence number than one already seen)"
    assert d.lines() == []                          # nothing new
    d.source = "10.0.0.9"
    d["bad_mac"] += 3
    assert d.grown and d.lines() == ["network: 3 bad_mac: datagrams with a missing or wrong MAC; from 10.0.0.9 (3)"]
    assert d["bad_mac"] == 503 and dict(d) == {"bad_mac": 503, "evicted": 500, "stale": 2}   # the JSON counts


def test_keys_and_tags():
    mac = auth.join_mac("pw", b"n" * 16, "alice")
    k1 = auth.datagram_key("pw", mac)
    assert len(k1) == 32 and k1 != auth.datagram_key("pw", auth.join_mac("pw", b"m" * 16, "alice"))
    assert k1 != auth.datagram_key("other", mac)
    msg = P.encode(P.State(2, 1.0, 1, 2, 0, 0, 0, 0, 100, True), 2, 7, 1.0)
    sealed = auth.seal(k1, msg)
    assert len(sealed) == len(msg) + auth.TAG_SIZE == 44
    assert auth.unseal(k1, sealed) == msg
    assert auth.unseal(k1[::-1], sealed) is None
    # 30 Hz to 7 peers stays under 16 KB/s of message bytes with the tag
    assert len(sealed) * 30 * 7 < 16 * 1024


def test_every_truncation_and_bit_flip_of_a_sealed_datagram_is_refused():
    key = auth.datagram_key("pw", bytes(32))
    sealed = auth.seal(key, P.encode(P.State(2, 1.0, 1, 2, 0, 0, 0, 0, 100, True), 2, 7, 1.0))
    for k in range(len(sealed)):
        assert auth.unseal(key, sealed[:k]) is None
    for bit in range(len(sealed) * 8):
        flipped = bytearray(sealed)
        flipped[bit // 8] ^= 1 << (bit % 8)
        assert auth.unseal(key, bytes(flipped)) is None
    rng = random.Random(3)
    for _ in range(2000):
        junk = rng.randbytes(rng.randrange(0, 80))
        assert auth.unseal(key, junk) is None
