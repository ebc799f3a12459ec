"""The simulated network the judge's tests run on: delays, jitter and reordering,
loss, partitions, all from one seed (the same seed, the same run)."""

from __future__ import annotations

from tanktool.net.simnet import SimNet


def _run(net: SimNet, n: int = 1000, dt: float = 0.01) -> list[tuple[float, int]]:
    got = []
    for k in range(n):
        net.send("a", "b", k)
        net.advance(dt)
        got += [(net.now, p) for _, _, p in net.deliver()]
    for _ in range(100):
        net.advance(dt)
        got += [(net.now, p) for _, _, p in net.deliver()]
    return got


def test_delay_and_order():
    got = _run(SimNet(delay=0.05))
    assert [p for _, p in got] == list(range(1000))
    assert all(0.05 - 1e-9 <= t - p * 0.01 <= 0.06 + 1e-9 for t, p in got)   # 50 ms, within a tick


def test_jitter_reorders_and_loss_drops_deterministically():
    a, b = _run(SimNet(seed=3, delay=0.05, jitter=0.15, loss=0.05)), _run(SimNet(seed=3, delay=0.05, jitter=0.15,
                                                                                 loss=0.05))
    assert a == b
    order = [p for _, p in a]
    assert 900 < len(order) < 990 and order != sorted(order)
    assert all(0.05 - 1e-9 <= t - p * 0.01 <= 0.21 + 1e-9 for t, p in a)


def test_partition_cuts_both_ways_for_its_span():
    net = SimNet()
    net.partition(1.0, 2.0, ["a"], ["b", "c"])
    seen = []
    for k in range(300):
        net.send("a", "b", ("ab", k))
        net.send("c", "a", ("ca", k))
        net.send("b", "c", ("bc", k))
        net.advance(0.01)
        seen += [p for _, _, p in net.deliver()]
    cut = {k for tag, k in seen if tag in ("ab", "ca")}
    assert not any(100 <= k < 200 for k in cut) and len(cut) == 200
    assert len([1 for tag, _ in seen if tag == "bc"]) == 300               # inside one side: untouched
    assert net.cut == 200
