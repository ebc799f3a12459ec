"""``tanktool play --watch MODEL``: the authoring loop.

The model is imported into a scratch bundle (a fresh folder under the system's temp
folder, removed when the game ends) and played.  While the window is open the model's
file (and a ``.mtl`` of the same name beside it) is watched: when it changes on disk
it is imported again **in the background** (the game keeps running) into a new
scratch bundle, and the running match is moved onto the new arena, every tank put
back where it was when it still fits there (ground under it, no wall through it),
else at a spawn point.  An import that fails leaves the last good arena playing and
its one-line error shown in the window.

:class:`ModelWatch` is the watching and importing, with no window: tests drive it
(and :func:`carry_over`) directly.
"""

from __future__ import annotations

import shutil
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

#: how often the model's file is looked at [s]
POLL_S = 0.4


class ModelWatch:
    """A model file and the scratch bundles imported from it."""

    def __init__(self, model: str | Path) -> None:
        self.model = Path(model)
        self.root = Path(tempfile.mkdtemp(prefix="tanktool-watch-"))
        self.imports = 0
        self._stamp = self._read_stamp()
        self._seen_at = 0.0
        self._job: threading.Thread | None = None
        self._done: tuple[str, Any] | None = None

    def _read_stamp(self) -> tuple:
        out = []
        for p in (self.model, self.model.with_suffix(".mtl")):
            try:
                st = p.stat()
                out.append((st.st_mtime_ns, st.st_size))
            except OSError:
                out.append(None)
        return tuple(out)

    def import_now(self) -> Path:
        """Import the model into a new scratch bundle; returns it.  Raises TanktoolError
        (one line naming the file) when the model cannot be imported."""
        from ..importer import import_arena

        self.imports += 1
        out = self.root / f"import{self.imports}"
        import_arena(self.model, out, name=self.model.stem, force=True)
        return out

    def poll(self, now: float | None = None) -> tuple[str, Any] | None:
        """Look at the file (at most every ``POLL_S``): a change starts an import in the
        background.  Returns ("ok", bundle) or ("error", message) when an import has
        finished since the last call, else None."""
        now = time.monotonic() if now is None else now
        if self._done is not None and (self._job is None or not self._job.is_alive()):
            done, self._done, self._job = self._done, None, None
            return done
        if self._job is not None or now - self._seen_at < POLL_S:
            return None
        self._seen_at = now
        stamp = self._read_stamp()
        if stamp == self._stamp:
            return None
        self._stamp = stamp
        self._job = threading.Thread(target=self._run, name="tanktool-watch", daemon=True)
        self._job.start()
        return None

    def _run(self) -> None:
        from ..errors import TanktoolError

        try:
            self._done = ("ok", self.import_now())
        except TanktoolError as e:
            self._done = ("error", str(e))
        except Exception as e:          # an importer's bug must not take the game down
            self._done = ("error", f"{self.model}: import failed ({type(e).__name__}: {e})")

    def wait(self, timeout: float = 120.0) -> None:
        """Wait for an import under way (tests)."""
        if self._job is not None:
            self._job.join(timeout)

    def close(self) -> None:
        """Remove the scratch bundles (all of them made here)."""
        self.wait(30.0)
        shutil.rmtree(self.root, ignore_errors=True)


def fits(world: Any, index: int, x: float, z: float, heading: float, y: float) -> bool:
    """Put tank ``index`` at (x, z) facing ``heading`` near height ``y``; whether it fits
    there (ground under it on some level, no wall through its hull).  Leaves it there."""
    t = world.tanks[index]
    t.place(x, z, heading)
    ground = world.ground        # every world has one (a flat arena's: sim.flat_ground.FlatGround)
    level = ground.locate(t.x, t.z, y)
    if level < 0:
        return False
    t.level, t.y = level, ground.height(t.x, t.z, level)
    x0, z0 = world.bounds[0]
    x1, z1 = world.bounds[1]
    if not (x0 < t.x < x1 and z0 < t.z < z1):
        return False
    contacts = world.detect_collisions([index]).walls
    # wall_contacts: [((px, pz, nx, nz, depth), wall), ...] per tank
    return not any(i == index and any(c[0][4] > 0.05 for c in found) for i, found in contacts)


def carry_over(old: Any, new: Any) -> list[bool]:
    """Put every tank of session ``new`` where the same tank of ``old`` is, when it fits
    (else it stays at its spawn point); its score and state come along.  Returns which
    tanks were put back."""
    out = []
    for a, b in zip(old.world.tanks, new.world.tanks):
        spawn = (b.x, b.z, b.heading, getattr(b, "level", 0), float(getattr(b, "y", 0.0)))
        ok = a.alive and fits(new.world, b.index, *a.position, a.heading, float(getattr(a, "y", 0.0)))
        if not ok:
            b.place(*spawn[:3])
            if hasattr(b, "level"):
                b.level, b.y = spawn[3], spawn[4]
        b.kills, b.deaths, b.hp = a.kills, a.deaths, a.hp if a.alive else b.hp
        out.append(ok)
    new.prev = new._poses()
    return out


def moved_session(old: Any, menu: Any, config: Any) -> tuple[Any, str]:
    """A new session on the menu's (just re-imported) arena with its choices and the
    configuration's seed, rules and driver, the tanks carried over from ``old``; and the
    line saying so."""
    from .session import GameSession

    new = GameSession(str(menu.arena.value), menu.vehicle.value, bots=int(menu.bots.value), seed=config.seed,
                      difficulty=str(menu.difficulty.value), player=True, bot=config.opponents.driver,
                      rules=config.rules)
    back = carry_over(old, new)
    return new, f"{config.watch.model.name} reloaded: {sum(back)} of {len(back)} tanks where they were"
