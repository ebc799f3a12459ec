"""Time a pipeline per stage without touching it: named functions wrapped in place.

``Profile(HOOKS)`` replaces each hooked function with a timing wrapper wherever it is
bound (the module that defines it and every tanktool module that imported it by
name, since ``from x import f`` copies the reference), and restores them all on
exit.  Time is *exclusive*: a hooked call inside another hooked call is charged to
its own stage and taken off its caller's, so the stages add up to at most the whole
and "other" is what no hook covers.  A hooked call in a worker thread (the heightfield's
bands, the grids compressed while a picture is drawn) runs beside the main thread's
stage, so it is kept apart, in ``thread_stages``: adding it in would count the same
wall time twice (a negative "other").  A hook whose module or name does not exist
(yet) is skipped, so the bench keeps working while the pipeline changes.

    HOOKS = [("rasterise", "tanktool.geometry.heightfield:rasterize"),
             ("quadtree", "tanktool.nav.quadtree:WallQuadtree.build")]   # a classmethod
    with Profile(HOOKS) as prof:
        run_the_import()
    prof.stages  # {"rasterise": seconds, ...}, main thread: they add up to <= the whole
    prof.thread_stages  # the same for hooked calls in worker threads
    prof.peak_mb  # {"rasterise": the largest resident size seen during it, ...}

With ``memory=True`` a thread samples the process's resident size every 20 ms
(/proc/self/statm) and charges it to the stage running then (the innermost hooked
call): a stage's peak is approximate (it misses spikes shorter than a sample) but
shows where the memory goes.
"""

from __future__ import annotations

import importlib
import inspect
import os
import sys
import threading
import time
from collections import defaultdict
from typing import Any, Callable


class Profile:
    """Exclusive seconds per stage over the hooked functions (see the module docstring)."""

    def __init__(self, hooks: list[tuple[str, str]], memory: bool = False):
        self.hooks = hooks
        self.stages: dict[str, float] = defaultdict(float)
        self.thread_stages: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self.peak_mb: dict[str, float] = defaultdict(float)
        self._memory = memory
        self._names: list[str] = ["other"]
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._stack: list[float] = []
        self._local = threading.local()
        self._undo: list[tuple[Any, str, Any]] = []
        self.missing: list[str] = []

    def _frames(self) -> tuple[list[float], list[str], dict[str, float]]:
        """This thread's stack of inner times, of stage names, and where its time goes:
        a hooked call in a worker thread is charged to ``thread_stages`` without taking
        it off the stage the main thread is in (the sampler follows the main thread's
        names)."""
        loc = self._local
        if not hasattr(loc, "stack"):
            main = threading.current_thread() is threading.main_thread()
            loc.stack, loc.names, loc.sink = ((self._stack, self._names, self.stages) if main
                                              else ([], ["other"], self.thread_stages))
        return loc.stack, loc.names, loc.sink

    def _wrap(self, stage: str, fn: Callable) -> Callable:
        calls, frames = self.calls, self._frames

        def timed(*args, **kwargs):
            stack, names, stages = frames()
            t0 = time.perf_counter()
            stack.append(0.0)
            names.append(stage)
            try:
                return fn(*args, **kwargs)
            finally:
                names.pop()
                inner = stack.pop()
                dt = time.perf_counter() - t0
                stages[stage] += dt - inner
                calls[stage] += 1
                if stack:
                    stack[-1] += dt

        timed.__wrapped__ = fn  # type: ignore[attr-defined]
        timed.__name__ = getattr(fn, "__name__", "timed")
        return timed

    def _sample(self) -> None:
        page = os.sysconf("SC_PAGE_SIZE") / 2 ** 20
        try:
            statm = open("/proc/self/statm")
        except OSError:
            return
        with statm:
            while not self._stop.wait(0.02):
                statm.seek(0)
                rss = int(statm.read().split()[1]) * page
                stage = self._names[-1]
                if rss > self.peak_mb[stage]:
                    self.peak_mb[stage] = rss

    def __enter__(self) -> "Profile":
        if self._memory:
            self._thread = threading.Thread(target=self._sample, daemon=True)
            self._thread.start()
        for stage, target in self.hooks:
            mod_name, _, attr = target.partition(":")
            try:
                mod = importlib.import_module(mod_name)
            except ImportError:
                self.missing.append(target)
                continue
            owner, name = mod, attr
            if "." in attr:  # Class.method
                cls_name, name = attr.split(".", 1)
                owner = getattr(mod, cls_name, None)
            raw = inspect.getattr_static(owner, name, None) if owner is not None else None
            if raw is None:
                self.missing.append(target)
                continue
            if isinstance(raw, (classmethod, staticmethod)):
                wrapped = type(raw)(self._wrap(stage, raw.__func__))
                self._undo.append((owner, name, raw))
                setattr(owner, name, wrapped)
                continue
            timed = self._wrap(stage, raw)
            # every module holding this very function object: its own and importers'
            for m in list(sys.modules.values()):
                if m is None or not (getattr(m, "__name__", "") or "").startswith(("tanktool", mod_name)):
                    continue
                for key, val in list(vars(m).items()):
                    if val is raw:
                        self._undo.append((m, key, raw))
                        setattr(m, key, timed)
            if owner is not mod:  # a plain method on a class
                self._undo.append((owner, name, raw))
                setattr(owner, name, timed)
        return self

    def __exit__(self, *exc) -> None:
        if self._thread is not None:
            self._stop.set()
            self._thread.join()
        for owner, name, raw in reversed(self._undo):
            setattr(owner, name, raw)
        self._undo.clear()


#: the walkable surface's stages, as bench/walkable.py and bench/import_arena.py time them
SURFACE_HOOKS = [
    ("rasterise", "tanktool.geometry.heightfield:rasterize"),
    ("filters", "tanktool.geometry.heightfield:filter_spans"),
    ("heightfield", "tanktool.geometry.heightfield:build_heightfield"),
    ("links", "tanktool.nav.walkable:link_spans"),
    ("distance", "tanktool.nav.walkable:chamfer_clearance"),
    ("regions", "tanktool.nav.walkable:components"),
    ("levels", "tanktool.nav.walkable:stack_levels"),
    ("surface", "tanktool.nav.walkable:build_surface"),
]
