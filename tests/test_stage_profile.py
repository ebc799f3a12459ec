"""bench/stage_profile.py: a hooked call in a worker thread is kept apart from the main
thread's stages, so the stages never add up to more than the wall time (a bench's
"other", the whole less the stages, was negative when band threads rasterised)."""

from __future__ import annotations

import importlib.util
import sys
import threading
import time
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _profile_class():
    spec = importlib.util.spec_from_file_location("stage_profile", ROOT / "bench" / "stage_profile.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.Profile


def _fake_pipeline(monkeypatch) -> types.ModuleType:
    mod = types.ModuleType("fake_pipeline")

    def band():
        time.sleep(0.05)

    def build():  # two bands at once, as the tiled heightfield runs them
        threads = [threading.Thread(target=mod.band) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()

    mod.band, mod.build = band, build
    monkeypatch.setitem(sys.modules, "fake_pipeline", mod)
    return mod


def test_worker_thread_time_is_kept_apart(monkeypatch):
    mod = _fake_pipeline(monkeypatch)
    Profile = _profile_class()
    with Profile([("rasterise", "fake_pipeline:band"), ("heightfield", "fake_pipeline:build")]) as prof:
        t0 = time.perf_counter()
        mod.build()
        total = time.perf_counter() - t0
    assert set(prof.stages) == {"heightfield"}
    assert sum(prof.stages.values()) <= total
    assert prof.stages["heightfield"] >= 0.05             # the main thread waited for the bands
    assert 0.1 <= prof.thread_stages["rasterise"] <= 2 * total   # both bands' time, beside it
    assert prof.calls["rasterise"] == 2
    assert mod.band.__name__ == "band" and not hasattr(mod.band, "__wrapped__")   # put back


def test_main_thread_calls_stay_exclusive(monkeypatch):
    mod = _fake_pipeline(monkeypatch)
    Profile = _profile_class()
    with Profile([("rasterise", "fake_pipeline:band")]) as prof:
        mod.band()
    assert prof.stages["rasterise"] >= 0.05
    assert not prof.thread_stages
