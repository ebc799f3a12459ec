"""Top view of a match's final state: walls, each tank's footprint, heading and trail,
shells in flight, where the hits and kills happened, and the scoreboard."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any


def save_match_picture(result: Any, path: str | os.PathLike, dpi: int = 110) -> None:
    """Draw ``result`` (a ``sim.match.MatchResult``) and write a PNG atomically."""
    import io

    import matplotlib

    if os.environ.get("DISPLAY") is None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    from ..formats.bundle import atomic_write_bytes

    world, report = result.world, result.report
    (x0, z0), (x1, z1) = world.bounds.tolist()
    w, h = x1 - x0, z1 - z0
    fig_w = 11.0
    fig_h = max(4.5, min(fig_w * h / max(w, 1e-9) * 0.72, 11.0))
    fig, (ax, side) = plt.subplots(1, 2, figsize=(fig_w, fig_h), gridspec_kw={"width_ratios": [3.2, 1]})
    ax.set_facecolor("#f4f1ea")
    seg = world.walls.segments
    for (a, b) in seg.tolist():
        ax.plot([a[0], b[0]], [a[1], b[1]], color="#3a3a3a", lw=2.2, solid_capstyle="round", zorder=2)
    colors = plt.get_cmap("tab10").colors
    names = world.names
    # trails and hits
    for i, tr in enumerate(result.trails):
        xs = [p[0] for p in tr]
        zs = [p[1] for p in tr]
        ax.plot(xs, zs, color=colors[i % 10], lw=1.0, alpha=0.45, zorder=1)
    for e in report["events"]:
        x, z = e["position"]
        if e["kind"] == "hit":
            ax.plot(x, z, marker="x", color="#c0392b", ms=5, mew=1.4, zorder=3)
        elif e["kind"] == "kill":
            ax.plot(x, z, marker="*", color="#111111", ms=12, zorder=3)
    for s in world.shells:
        ax.plot([s.x - s.vx * 0.02, s.x], [s.z - s.vz * 0.02, s.z], color="#e67e22", lw=2, zorder=5)
    for t in world.tanks:
        col = colors[t.index % 10]
        fp = [t.to_world(lx, lz) for lx, lz in t.spec.footprint]
        ax.add_patch(Polygon(fp, closed=True, fc=col if t.alive else "none", ec=col,
                             lw=1.5, ls="-" if t.alive else "--", alpha=0.9, zorder=4))
        L = t.spec.muzzle_local[0] * 1.6
        ax.plot([t.x, t.x + t.c * L], [t.z, t.z + t.s * L], color="black", lw=1.6, zorder=5)
        label = t.name if t.alive else f"{t.name} (dead)"
        ax.annotate(label, (t.x, t.z), xytext=(6, 6), textcoords="offset points", fontsize=8,
                    color="black", zorder=6, bbox=dict(boxstyle="round,pad=0.15", fc="white", ec=col, alpha=0.8))
    pad = 0.03 * max(w, h)
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(z0 - pad, z1 + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(f"{report['arena']}: {len(world.tanks)} × {report['vehicle']}, seed {report['seed']}, "
                 f"t = {report['seconds']:g} s", fontsize=10)
    ax.grid(True, color="white", lw=0.8, zorder=0)
    # scoreboard
    side.axis("off")
    rows = sorted(report["tanks"], key=lambda d: (-d["kills"], d["deaths"]))
    cells = [[d["name"], d["kills"], d["deaths"], f"{d['hits']}/{d['shots']}", d["wall_bumps"]] for d in rows]
    table = side.table(cellText=cells, colLabels=["tank", "K", "D", "hit/shot", "bumps"], loc="upper center",
                       cellLoc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    table.scale(1.0, 1.3)
    for r, d in enumerate(rows, start=1):
        table[r, 0].set_facecolor(colors[names.index(d["name"]) % 10])
        table[r, 0].set_alpha(0.6)
    side.text(0.5, 0.02, "x hit   * kill   — trail\norange: shells in flight", transform=side.transAxes,
              ha="center", va="bottom", fontsize=8, color="#555555")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    atomic_write_bytes(Path(path), buf.getvalue())
