"""Commands: the only way anything drives a tank.

Keyboard, joystick, computer agent, scripted bot and network peer all produce the
same :class:`Command` values, one per tank per step.  Strengths are analogue in
[-1, 1] so a joystick axis maps straight onto them; keys give -1, 0 or +1.

Sign conventions (world axes of DESIGN.md, heading θ, forward f = (cos θ, sin θ)):

- ``advance`` > 0 drives forward along f, < 0 reverses;
- ``rotate`` > 0 turns right, i.e. towards the right-hand side (−f_z, f_x), which is
  the direction of increasing θ;
- ``strafe`` > 0 pushes to the right, along (−sin θ, cos θ);
- ``fire`` asks for a shell; the weapon fires when its reload interval has passed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import TanktoolError


def _clamp(v: float) -> float:
    # NaN from a broken joystick driver must not poison the simulation
    if not math.isfinite(v):
        return 0.0
    return -1.0 if v < -1.0 else 1.0 if v > 1.0 else float(v)


@dataclass(frozen=True, slots=True)
class Command:
    """What one tank wants during one step; strengths are clamped to [-1, 1]."""

    advance: float = 0.0
    rotate: float = 0.0
    strafe: float = 0.0
    fire: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "advance", _clamp(self.advance))
        object.__setattr__(self, "rotate", _clamp(self.rotate))
        object.__setattr__(self, "strafe", _clamp(self.strafe))
        object.__setattr__(self, "fire", bool(self.fire))

    def to_tuple(self) -> tuple[float, float, float, bool]:
        return (self.advance, self.rotate, self.strafe, self.fire)

    @classmethod
    def from_keys(cls, forward: bool = False, back: bool = False, left: bool = False,
                  right: bool = False, strafe_left: bool = False, strafe_right: bool = False,
                  fire: bool = False) -> "Command":
        """Digital input (keys, buttons) as full-strength commands."""
        return cls(advance=float(forward) - float(back), rotate=float(right) - float(left),
                   strafe=float(strafe_right) - float(strafe_left), fire=fire)


IDLE = Command()


def parse_command(text: str) -> Command:
    """Parse ``"advance rotate strafe fire"`` (e.g. ``"1 -0.5 0 1"``), for scripts and tests."""
    parts = text.split()
    if len(parts) != 4:
        raise TanktoolError(f"command {text!r}: expected 4 fields 'advance rotate strafe fire'")
    try:
        a, r, s = (float(p) for p in parts[:3])
        f = int(parts[3])
    except ValueError:
        raise TanktoolError(f"command {text!r}: expected three numbers and 0 or 1") from None
    if f not in (0, 1):
        raise TanktoolError(f"command {text!r}: fire must be 0 or 1")
    return Command(a, r, s, bool(f))
