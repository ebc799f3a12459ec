"""Rendering speed and the CPU cost of a frame, headless, 8 tanks in each bundled arena.

For every bundled arena: a session of 8 scripted bots runs 60 frames to warm up, then
for ``--frames`` frames of 1/60 s each this times

- the 3D view at 1280x720 through EGL (Mesa llvmpipe here), HUD included, the frame
  read back to memory as a screenshot does (``3d fps``), and without the read-back
  (``3d draw fps``: what a window would show, ``ctx.finish()`` waits for the GPU);
- the top view drawn with pygame at the same size (``top fps``);
- the CPU work of the frame besides drawing: two simulation steps of 1/120 s with the
  bots deciding (``sim+bots ms``) and the 3D sound (``audio ms``: the listener and 8
  engine voices updated, new chunks spatialised and queued on SDL's dummy audio
  device, one-shot sounds for the frame's events), measured as CPU time of the process
  (``time.process_time``) so that other jobs on the machine do not inflate it.

Goals (issue 8): at least 30 fps in 3D on Mesa's software renderer; under 4 ms of
CPU per frame for simulation + bots + audio.

    python bench/render.py [--frames N] [--size WxH] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pygame  # noqa: E402

from tanktool.audio import Sound  # noqa: E402
from tanktool.game.headless import FRAME, run_frames  # noqa: E402
from tanktool.game.render_top import TopView  # noqa: E402
from tanktool.game.session import GameSession  # noqa: E402
from tanktool.game.sounds import GameAudio  # noqa: E402


def bench_arena(name: str, frames: int, size: tuple[int, int], seed: int) -> dict:
    from tanktool.game.render3d import Renderer3D

    session = GameSession(name, bots=8, seed=seed, player=False)
    run_frames(session, 60)
    steps_per_frame = max(int(round(FRAME / session.dt)), 1)
    audio = GameAudio(session, Sound())
    sim_t = audio_t = 0.0
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
        sim_t += t1 - t0
        audio_t += t2 - t1
    audio.close()

    r3d = Renderer3D(session, size)
    r3d.render(1.0, 0.0)                       # compile shaders, upload, first-frame costs
    t0 = time.perf_counter()
    for _ in range(frames):
        r3d.render(1.0, 30.0)
    t3d = time.perf_counter() - t0
    # the same frames as a window would draw them: no read-back
    r3d.own_ctx = False
    t0 = time.perf_counter()
    for _ in range(frames):
        r3d.render(1.0, 30.0)
        r3d.ctx.finish()
    t3d_draw = time.perf_counter() - t0
    r3d.own_ctx = True
    r3d.release()

    top = TopView(session, size)
    surf = pygame.Surface(size)
    top.draw(surf)
    t0 = time.perf_counter()
    for _ in range(frames):
        top.draw(surf, 1.0, 30.0)
    ttop = time.perf_counter() - t0
    sim_ms, audio_ms = 1000 * sim_t / frames, 1000 * audio_t / frames
    return {
        "arena": name, "tanks": len(session.world.tanks), "frames": frames,
        "fps_3d": round(frames / t3d, 1), "fps_3d_draw": round(frames / t3d_draw, 1),
        "fps_top": round(frames / ttop, 1),
        "sim_bots_ms": round(sim_ms, 3), "audio_ms": round(audio_ms, 3), "cpu_ms": round(sim_ms + audio_ms, 3),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true", help="one JSON object with the same figures")
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    pygame.init()
    from tanktool.game.app import bundled

    rows = [bench_arena(a, args.frames, size, args.seed) for a in bundled("arenas")]
    try:
        import moderngl

        ctx = moderngl.create_standalone_context(backend="egl")
        renderer = ctx.info.get("GL_RENDERER", "?")
        ctx.release()
    except Exception as e:  # the 3D numbers above would have failed already
        renderer = f"unavailable ({e})"
    result = {"size": list(size), "renderer": renderer, "cpus": os.cpu_count(),
              "goals": {"fps_3d_min": 30, "cpu_ms_max": 4.0}, "arenas": rows}
    if args.json:
        print(json.dumps(result))
        return
    print(f"{size[0]}x{size[1]}, 8 tanks, {args.frames} frames; OpenGL: {renderer}; {os.cpu_count()} CPUs")
    head = f"{'arena':<10} {'3d fps':>7} {'3d draw fps':>11} {'top fps':>8} {'sim+bots ms':>11} {'audio ms':>9} {'cpu ms':>7}"
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['arena']:<10} {r['fps_3d']:>7.1f} {r['fps_3d_draw']:>11.1f} {r['fps_top']:>8.1f} "
              f"{r['sim_bots_ms']:>11.3f} {r['audio_ms']:>9.3f} {r['cpu_ms']:>7.3f}")
    print("goals: 3d fps >= 30 on Mesa llvmpipe; cpu ms (sim + bots + audio) < 4 per frame")


if __name__ == "__main__":
    main()
