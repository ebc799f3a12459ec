"""What a world step reports: its events (out of sim/world.py)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

EVENT_KINDS = ("shot", "hit", "kill", "wall_bump", "respawn", "shielded", "match_end")


@dataclass(frozen=True, slots=True)
class Event:
    """Something that happened during a step.

    ``tank`` is the actor (shooter, killer, the tank that bumped or respawned);
    ``other`` the victim of a hit, kill or shielded hit (a shell that met a tank under
    spawn protection), or the wall index of a bump (-1 if none);
    ``value`` the damage of a hit or the impulse [N s] of a bump.  ``match_end``:
    ``tank`` is the winner (-1: a draw), at the winner's position.
    """

    step: int
    t: float
    kind: str
    tank: int
    x: float
    z: float
    other: int = -1
    value: float = 0.0

    def to_dict(self, names: Sequence[str] | None = None) -> dict[str, Any]:
        d: dict[str, Any] = {"t": round(self.t, 4), "step": self.step, "kind": self.kind,
                             "tank": names[self.tank] if names else self.tank}
        if self.kind in ("hit", "kill", "shielded"):
            d["victim"] = names[self.other] if names else self.other
        if self.kind == "match_end":
            d["tank"] = (names[self.tank] if names else self.tank) if self.tank >= 0 else None
        if self.kind == "wall_bump":
            d["wall"] = self.other
        if self.kind in ("hit", "wall_bump"):
            d["value"] = round(self.value, 3)
        d["position"] = [round(self.x, 3), round(self.z, 3)]
        return d
