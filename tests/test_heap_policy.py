"""memory.frozen_heap and memory.give_back's heap threshold (the import's CPU round)."""

from __future__ import annotations

import gc

import pytest

from tanktool import memory


def test_frozen_heap_freezes_while_running_and_unfreezes_after():
    seen = []

    @memory.frozen_heap
    def inner() -> int:
        seen.append(("inner", gc.get_freeze_count()))
        return 2

    @memory.frozen_heap
    def outer() -> int:
        seen.append(("outer", gc.get_freeze_count()))
        return inner() + 1   # nested: left frozen, not unfrozen by the inner call

    assert gc.get_freeze_count() == 0
    assert outer() == 3
    assert seen[0][1] > 0 and seen[1][1] == seen[0][1]
    assert gc.get_freeze_count() == 0


def test_frozen_heap_unfreezes_on_error_and_leaves_a_callers_freeze_alone():
    @memory.frozen_heap
    def boom() -> None:
        raise ValueError("bad input")

    with pytest.raises(ValueError):
        boom()
    assert gc.get_freeze_count() == 0
    gc.freeze()   # the caller's own freeze is not undone
    try:
        before = gc.get_freeze_count()
        with pytest.raises(ValueError):
            boom()
        assert gc.get_freeze_count() == before
    finally:
        gc.unfreeze()


def test_give_back_keeps_a_small_heap(monkeypatch):
    calls = []
    monkeypatch.setattr(memory, "_trim", lambda pad: calls.append(pad))
    monkeypatch.setattr(memory, "heap_bytes", lambda: memory.GIVE_BACK_HEAP - 1)
    assert memory.give_back(memory.GIVE_BACK_MIN) is False   # a small heap keeps its pages
    assert memory.give_back(memory.GIVE_BACK_MIN - 1) is False   # a small build gives nothing back
    monkeypatch.setattr(memory, "heap_bytes", lambda: memory.GIVE_BACK_HEAP)
    assert memory.give_back(memory.GIVE_BACK_MIN) is True
    monkeypatch.setattr(memory, "heap_bytes", lambda: None)   # mallinfo2 missing: trimmed as before
    assert memory.give_back(memory.GIVE_BACK_MIN) is True
    assert calls == [0, 0]
