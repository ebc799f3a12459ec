"""Rendering speed at each quality preset beside a minimal reference scene, and the CPU
cost of a frame, headless, 8 tanks in each bundled arena.

For every bundled arena a match of 8 computer agents is warmed up for 60 frames, then:

- **3D at every preset** (game/quality.py: low, medium = the default, high = everything
  on) at 1280x720 through EGL (Mesa llvmpipe here), HUD and effects included, the
  frame read back to memory as a screenshot does (``fps``), and beside each, in the
  same run, its **reference**: the same triangles (arena and the 8 tanks; an arena lit
  per vertex is split into more) drawn with one colour, depth test, no light, texture,
  shadow, sky, effect or HUD, read back the same way.  Presets and references take
  turns, ``--frames`` frames at a time for ``--rounds`` rounds, while the match goes on
  (2 steps of 1/120 s between frames, not timed), so each sees the same load; the
  **ratio** preset fps / reference fps (median of the rounds) is the figure to compare
  across machines (each preset's renderer has its own headless context, made current
  for its frames: with one current for all, the others drew almost nothing):
  llvmpipe renders on every core, so on a shared machine the absolute fps follow the
  other jobs, the ratio much less.  Beside them the CPU time the frame took on every
  thread of the process (llvmpipe's rasteriser threads included: ``cpu ms/frame``),
  which on a loaded machine moves less than the wall clock;
- ``fps_3d_draw``: the default preset without the read-back (what a window shows,
  ``ctx.finish()`` waits for the rasteriser);
- the top view drawn with pygame at the same size (``top fps``);
- the CPU work of the frame besides drawing: two simulation steps with the agents
  deciding (``sim+bots ms``), the 3D sound (``audio ms``: listener and 8 engine voices
  updated, chunks spatialised and queued on SDL's dummy device, one-shot sounds for the
  events) and the particles (``fx ms``: bursts, dust, the update), as CPU time of the
  process (``time.process_time``) so that other jobs do not inflate it.

Goals (issue 20): on a quiet 2-core machine >= 60 fps at the default preset and >= 30
fps with everything on; under 4 ms of CPU per frame for simulation + agents + sound.
The load average is printed before and after: above about 0.5 before the run the
absolute fps are not those of a quiet machine (the run itself adds about 2: llvmpipe
renders on both cores).

    python bench/render.py [--frames N] [--rounds R] [--size WxH] [--json]

``--window`` measures instead the game window's own loop (game/app.py's frame: events,
the fixed-step simulation with the agents, particles, HUD, the 3D view at the default
preset, the buffer swap) on real time as the window runs it, in SDL's offscreen video
driver (an EGL window drawn by llvmpipe, nothing shown): 8 tanks (yours, standing at its
spawn, and 7 normal agents), ``--frames`` frames after 30 to warm up: frames a second,
and the CPU time a frame takes, all threads and the main thread alone.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
# --window plays the game window's own loop in SDL's offscreen window (EGL, llvmpipe, as a
# real window draws, nothing shown); everything else needs no window at all
os.environ.setdefault("SDL_VIDEODRIVER", "offscreen" if "--window" in sys.argv else "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")   # --json prints one JSON object, nothing else

import pygame  # noqa: E402

from tanktool.audio import Sound  # noqa: E402
from tanktool.game.headless import FRAME, run_frames  # noqa: E402
from tanktool.game.quality import DEFAULT, PRESETS  # noqa: E402
from tanktool.game.render_top import TopView  # noqa: E402
from tanktool.game.session import GameSession  # noqa: E402
from tanktool.game.sounds import GameAudio  # noqa: E402

#: the preset that stands for "everything on"
ALL_ON = "high"


def cpu_costs(session: GameSession, frames: int) -> dict:
    """CPU ms per frame of the simulation with its agents, of the sound and of the particles."""
    from tanktool.game.particles import SessionEffects

    steps_per_frame = max(int(round(FRAME / session.dt)), 1)
    audio = GameAudio(session, Sound())
    fx = SessionEffects(PRESETS[DEFAULT].particles)
    sim_t = audio_t = fx_t = 0.0
    # CPU time of this process, not wall time: on a machine shared with other jobs the
    # wall clock also counts the time spent waiting for a core
    for _ in range(frames):
        t0 = time.process_time()
        events = []
        for _ in range(steps_per_frame):
            events.extend(session.step())
        t1 = time.process_time()
        audio.on_events(events)
        audio.update(1.0)
        t2 = time.process_time()
        fx.sync(session)
        fx.particles.instances((0.0, 10.0, 0.0))
        t3 = time.process_time()
        sim_t += t1 - t0
        audio_t += t2 - t1
        fx_t += t3 - t2
    audio.close()
    return {"sim_bots_ms": round(1000 * sim_t / frames, 3), "audio_ms": round(1000 * audio_t / frames, 3),
            "cpu_ms": round(1000 * (sim_t + audio_t) / frames, 3), "fx_ms": round(1000 * fx_t / frames, 3)}


def bench_arena(name: str, frames: int, rounds: int, size: tuple[int, int], seed: int) -> dict:
    from tanktool.game.render3d import Renderer3D

    session = GameSession(name, bots=8, seed=seed, player=False)
    run_frames(session, 60)
    row = {"arena": name, "tanks": len(session.world.tanks), "frames": frames * rounds}
    row.update(cpu_costs(session, 120))

    renderers = {p: Renderer3D(session, size, quality=PRESETS[p]) for p in PRESETS}
    first = renderers[DEFAULT]
    row["triangles"] = first.triangles()
    for r in renderers.values():
        r.render(1.0, 30.0)                    # compile shaders, upload, first-frame costs
        r.render_reference(1.0)
    steps = max(int(round(FRAME / session.dt)), 1)

    cpu: dict[str, list[float]] = {}

    def frame_time(draw, key: str) -> float:
        total = used = 0.0
        for _ in range(frames):
            for _ in range(steps):
                session.step()
            for other in renderers.values():
                other.effects.sync(session, other.floor_y)
            t, c = time.perf_counter(), time.process_time()
            draw()
            total += time.perf_counter() - t
            used += time.process_time() - c
        # CPU time of every thread (llvmpipe's too) per frame: the work, whatever else runs
        cpu.setdefault(key, []).append(1000 * used / frames)
        return frames / max(total, 1e-9)

    fps: dict[str, list[float]] = {k: [] for k in [*PRESETS, "draw"]}
    ref: dict[str, list[float]] = {k: [] for k in PRESETS}
    for _ in range(rounds):
        for p, r in renderers.items():
            # the reference of a preset draws its triangles (the arena is split: light
            # and fog come from its vertices), right before it
            ref[p].append(frame_time(lambda r=r: r.render_reference(1.0), "ref " + p))
            fps[p].append(frame_time(lambda r=r: r.render(1.0, 30.0), p))

        def no_readback() -> None:
            with first.ctx:                     # each renderer has its own context: make it current
                first.own_ctx = False
                first.render(1.0, 30.0)
                first.ctx.finish()
                first.own_ctx = True

        fps["draw"].append(frame_time(no_readback, "draw"))
    row["reference_fps"] = round(statistics.median(ref[DEFAULT]), 1)
    row["presets"] = {p: {"fps": round(statistics.median(fps[p]), 1), "triangles": renderers[p].triangles(),
                          "reference_fps": round(statistics.median(ref[p]), 1),
                          "ratio": round(statistics.median([a / b for a, b in zip(fps[p], ref[p])]), 3),
                          "cpu_ms_frame": round(statistics.median(cpu[p]), 1),
                          "reference_cpu_ms_frame": round(statistics.median(cpu["ref " + p]), 1)}
                      for p in PRESETS}
    row["fps_3d"] = row["presets"][DEFAULT]["fps"]
    row["fps_3d_draw"] = round(statistics.median(fps["draw"]), 1)
    for r in renderers.values():
        r.release()

    top = TopView(session, size)
    surf = pygame.Surface(size)
    top.draw(surf)
    t0 = time.perf_counter()
    n = frames * 2
    for _ in range(n):
        top.draw(surf, 1.0, 30.0)
    row["fps_top"] = round(n / (time.perf_counter() - t0), 1)
    return row


def window_loop(name: str, frames: int, size: tuple[int, int]) -> dict:
    """The window's loop on ``name`` (see the module docstring): fps and CPU a frame."""
    import tempfile

    from tanktool.game.app import App
    from tanktool.game.config import MatchConfig, Opponents, ViewConfig

    cfg = MatchConfig(arena=name, opponents=Opponents(7, "normal"), view=ViewConfig("3d", size, False, DEFAULT),
                      sound=False)
    with tempfile.TemporaryDirectory() as tmp:      # the first start saves settings: not the user's
        app = App(None, cfg, settings_file=Path(tmp) / "settings.toml")
        app.start()
        try:
            if app.view != "3d":
                raise SystemExit(f"{name}: the window has no OpenGL 3.3 here ({app.notice})")
            last = time.perf_counter()

            def run(n: int) -> None:
                nonlocal last
                for _ in range(n):
                    now = time.perf_counter()
                    app.frame(now - last)
                    last = now

            run(30)
            t, cpu, main = time.perf_counter(), time.process_time(), time.thread_time()
            run(frames)
            wall = time.perf_counter() - t
            return {"arena": name, "fps": round(frames / wall, 1),
                    "cpu_ms_frame": round(1000 * (time.process_time() - cpu) / frames, 1),
                    "main_thread_ms_frame": round(1000 * (time.thread_time() - main) / frames, 1)}
        finally:
            app.stop()


def window_table(args: argparse.Namespace, size: tuple[int, int]) -> None:
    """``--window``: the window's loop on each arena, each in its own process."""
    from tanktool.game.app import bundled

    load = os.getloadavg()[0]
    names = [a for a in bundled("arenas") if not args.arena or a in args.arena]
    if len(names) == 1:
        rows = [window_loop(names[0], args.frames, size)]
    else:   # one process an arena: SDL's offscreen driver gives a process one GL window
        import subprocess

        rows = []
        for a in names:
            out = subprocess.run([sys.executable, __file__, "--window", "--json", "--arena", a, "--frames",
                                  str(args.frames), "--size", args.size], capture_output=True, text=True)
            if out.returncode != 0:
                raise SystemExit(out.stderr.strip().splitlines()[-1] if out.stderr.strip() else f"{a}: failed")
            rows += json.loads(out.stdout)["window"]
    if args.json:
        print(json.dumps({"size": list(size), "default": DEFAULT, "load_average_before": round(load, 2),
                          "window": rows}))
        return
    print(f"the window's loop, offscreen, {size[0]}x{size[1]}, {DEFAULT}, 8 tanks, {args.frames} frames; "
          f"load average {load:.2f} -> {os.getloadavg()[0]:.2f}")
    print(f"{'arena':<10} {'fps':>6} {'cpu ms':>7} {'main ms':>8}")
    for r in rows:
        print(f"{r['arena']:<10} {r['fps']:>6.1f} {r['cpu_ms_frame']:>7.1f} {r['main_thread_ms_frame']:>8.1f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=12, help="frames per preset per round")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--arena", action="append", help="only this bundled arena (repeatable)")
    ap.add_argument("--json", action="store_true", help="one JSON object with the same figures")
    ap.add_argument("--window", action="store_true",
                    help="the game window's own loop, offscreen (SDL's offscreen driver), --frames frames an arena")
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    pygame.init()
    from tanktool.game.app import bundled

    if args.window:
        window_table(args, size)
        return
    from tanktool.game.render3d import standalone_context

    load_before = os.getloadavg()
    arenas = [a for a in bundled("arenas") if not args.arena or a in args.arena]
    rows = [bench_arena(a, args.frames, args.rounds, size, args.seed) for a in arenas]
    load_after = os.getloadavg()
    try:
        ctx = standalone_context()
        renderer = ctx.info.get("GL_RENDERER", "?")
        ctx.release()
    except Exception as e:  # the 3D numbers above would have failed already
        renderer = f"unavailable ({e})"
    result = {"size": list(size), "renderer": renderer, "cpus": os.cpu_count(), "default": DEFAULT, "all_on": ALL_ON,
              "load_average": {"before": [round(v, 2) for v in load_before],
                               "after": [round(v, 2) for v in load_after]},
              "goals": {"fps_3d_min": 60, "fps_3d_all_on_min": 30, "cpu_ms_max": 4.0}, "arenas": rows}
    if args.json:
        print(json.dumps(result))
        return
    quiet = load_before[0] < 0.5            # the run itself adds about 2 to the load
    print(f"{size[0]}x{size[1]}, 8 tanks, {args.rounds} rounds of {args.frames} frames; OpenGL: {renderer}; "
          f"{os.cpu_count()} CPUs; load average {load_before[0]:.2f} -> {load_after[0]:.2f}"
          + ("" if quiet else " (NOT quiet: the absolute fps are not a quiet machine's; compare the ratios)"))
    names = list(PRESETS)
    head = (f"{'arena':<10} {'tris':>5} {'ref fps':>8} " + " ".join(f"{p + ' fps':>10} {'ratio':>6}" for p in names)
            + f" {'draw fps':>9} {'top fps':>8} {'sim+bots':>8} {'audio':>6} {'cpu ms':>7} {'fx ms':>6}")
    print(head)
    print("-" * len(head))
    for r in rows:
        cells = " ".join(f"{r['presets'][p]['fps']:>10.1f} {r['presets'][p]['ratio']:>6.3f}" for p in names)
        print(f"{r['arena']:<10} {r['triangles']:>5} {r['reference_fps']:>8.1f} {cells} {r['fps_3d_draw']:>9.1f} "
              f"{r['fps_top']:>8.1f} {r['sim_bots_ms']:>8.3f} {r['audio_ms']:>6.3f} {r['cpu_ms']:>7.3f} {r['fx_ms']:>6.3f}")
    print()
    head = f"{'cpu ms/frame':<12} " + " ".join(f"{p:>8} {'its ref':>8}" for p in names)
    print(head)
    for r in rows:
        print(f"{r['arena']:<12} " + " ".join(f"{r['presets'][p]['cpu_ms_frame']:>8.1f} "
                                             f"{r['presets'][p]['reference_cpu_ms_frame']:>8.1f}" for p in names))
    print(f"default preset: {DEFAULT}; everything on: {ALL_ON}.  Goals on a quiet 2-core machine: {DEFAULT} >= 60 fps, "
          f"{ALL_ON} >= 30 fps; cpu ms (sim + agents + sound) < 4 per frame")


if __name__ == "__main__":
    main()
