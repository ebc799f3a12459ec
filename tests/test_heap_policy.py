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
        total = inner() + 1
        seen.append(("after inner", gc.get_freeze_count()))   # nested: not unfrozen by the inner call
        return total

    assert gc.get_freeze_count() == 0
    assert outer() == 3
    # counts, not equalities: a frozen object freed by its refcount leaves the permanent generation
    assert [n for n, _ in seen] == ["outer", "inner", "after inner"] and all(c > 0 for _, c in seen)
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
        with pytest.raises(ValueError):
            boom()
        # still frozen (an unfreeze empties the permanent generation; its count may drop a
        # little meanwhile as frozen objects are freed by their refcount)
        assert gc.get_freeze_count() > 0
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
