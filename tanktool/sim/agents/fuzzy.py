"""The attack controller: zero-order Sugeno fuzzy logic (the paper's "lógica difusa").

Every input has a few *terms*, each a triangle peaking at one breakpoint and reaching
zero at its neighbours, with shoulders at both ends (flat 1 beyond the first and the
last breakpoint).  Such terms form a partition of unity: at any input the memberships
add up to 1.  A rule base is a table with one constant consequent per combination of
terms; the output is the membership-weighted sum of the consequents (product t-norm,
weighted-average defuzzification).  With one input that is piecewise-linear
interpolation of the consequents; with two it is bilinear.  Hence an output is
monotone in an input whenever the consequents are monotone along that input's axis of
the table, which is how every rule base below is written (and tested).

Inputs (per think; ``e`` and ``V`` are signed, positive = towards increasing heading,
i.e. to the right):

* ``V``  relative lateral speed [m/s]: the enemy's velocity minus our own (a shell
  inherits the shooter's velocity) across the line of sight.
* ``e``  angle error [rad]: the aim bearing (bearing + lead + aim noise) minus our
  heading.  The turn rule base reads the *predicted* error ``e - 0.2 s * omega`` (where
  the gun will point a moment from now), which damps the tank's slow turn response.
* ``|e|`` its size, and ``D`` the distance to the enemy [m].

Terms (breakpoints):

==========  ==================================================  ========================
input       terms                                               breakpoints
==========  ==================================================  ========================
V           left-fast, still, right-fast                        -10, 0, +10 m/s
e (turn)    NB, NS, Z, PS, PB                                   -0.3, -0.08, 0, 0.08, 0.3 rad
|e| (fire)  on-target, close, off                               0, 0.04, 0.1 rad
|e| (move)  aligned, off                                        0.1, 0.6 rad
D           near, medium, far                                   15, 45, 90 m
==========  ==================================================  ========================

Rules (consequents).  Turn is a ``Command`` strength; advance and strafe are wanted
speeds, as fractions of half the top speed, that ``Agent._drive`` turns into commands:

* lead: left-fast -> -asin(10/v_s); still -> 0; right-fast -> +asin(10/v_s)
  (v_s = shell speed: the intercept angle of a target crossing at 10 m/s)
* turn: NB -> -1, NS -> -0.6, Z -> 0, PS -> +0.6, PB -> +1
* fire readiness (fire when >= 0.5):

  ===========  =====  ======  ===
  |e| \\ D      near  medium  far
  ===========  =====  ======  ===
  on-target    1.0    1.0     0.8
  close        0.9    0.6     0.2
  off          0.0    0.0     0.0
  ===========  =====  ======  ===

* advance (x half the top speed, a wanted speed): aligned: near -0.7, medium -0.5,
  far 0.6; off: near -0.3, medium -0.2, far 0.2 (so it holds about 65 m where the
  arena allows: an aim error in angle misses more the farther the target, and the
  baseline's 3 degrees suffer more from it than our 1.5)
* strafe size (x half the top speed; the side flips every 1-2.5 s and away from walls):
  aligned: near 1.0, medium 0.9, far 0.6; off: near 0.5, medium 0.4, far 0.2

So: fire readiness falls with |e| and with D; advance rises with D (back off when
near, close in when far) and is damped when not aligned (turn first, then drive);
strafe size falls with D and with |e|; turn and lead rise with their inputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence


@dataclass(frozen=True)
class Variable:
    """A fuzzy input: named terms peaking at increasing breakpoints (a partition of unity)."""

    name: str
    terms: tuple[str, ...]
    peaks: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.terms) != len(self.peaks) or len(self.peaks) < 2:
            raise ValueError(f"{self.name}: need as many terms as breakpoints, at least 2")
        if any(b <= a for a, b in zip(self.peaks, self.peaks[1:])):
            raise ValueError(f"{self.name}: breakpoints must increase, got {self.peaks}")

    def memberships(self, x: float) -> list[float]:
        """Membership of ``x`` in each term; they add up to 1."""
        p = self.peaks
        out = [0.0] * len(p)
        if not x > p[0]:          # also catches NaN: treated as the first term
            out[0] = 1.0
            return out
        if x >= p[-1]:
            out[-1] = 1.0
            return out
        k = 0
        while x >= p[k + 1]:
            k += 1
        w = (x - p[k]) / (p[k + 1] - p[k])
        out[k], out[k + 1] = 1.0 - w, w
        return out

    def membership(self, term: str, x: float) -> float:
        return self.memberships(x)[self.terms.index(term)]


def sugeno1(var: Variable, consequents: Sequence[float], x: float) -> float:
    """One-input rule base: ``if x is term_k then y = consequents[k]``."""
    return sum(m * c for m, c in zip(var.memberships(x), consequents))


def sugeno2(a: Variable, b: Variable, table: Sequence[Sequence[float]], x: float, y: float) -> float:
    """Two-input rule base: ``if x is a_i and y is b_j then out = table[i][j]`` (product AND)."""
    ma, mb = a.memberships(x), b.memberships(y)
    return sum(wa * wb * table[i][j] for i, wa in enumerate(ma) if wa for j, wb in enumerate(mb) if wb)


V_LAT = Variable("lateral speed", ("left-fast", "still", "right-fast"), (-10.0, 0.0, 10.0))
ERROR = Variable("angle error", ("NB", "NS", "Z", "PS", "PB"), (-0.3, -0.08, 0.0, 0.08, 0.3))
AIM = Variable("|angle error| (aim)", ("on-target", "close", "off"), (0.0, 0.04, 0.1))
ALIGN = Variable("|angle error| (move)", ("aligned", "off"), (0.1, 0.6))
DIST = Variable("distance", ("near", "medium", "far"), (15.0, 45.0, 90.0))

TURN = (-1.0, -0.6, 0.0, 0.6, 1.0)
FIRE = ((1.0, 1.0, 0.8), (0.9, 0.6, 0.2), (0.0, 0.0, 0.0))
ADVANCE = ((-0.7, -0.5, 0.6), (-0.3, -0.2, 0.2))
STRAFE = ((1.0, 0.9, 0.6), (0.5, 0.4, 0.2))
#: fire when the readiness reaches this
FIRE_THRESHOLD = 0.5
#: how far ahead the turn rules look [s] (anticipates the gun's swing)
PREDICT = 0.2


@dataclass(frozen=True)
class AttackOutput:
    rotate: float
    advance: float
    strafe_size: float
    fire: float


class AttackController:
    """The rule bases above, for a gun of ``shell_speed`` [m/s]."""

    def __init__(self, shell_speed: float) -> None:
        lead = math.asin(min(V_LAT.peaks[-1] / max(shell_speed, 1e-9), 1.0))
        self.lead_consequents = (-lead, 0.0, lead)

    def lead(self, v_lat: float) -> float:
        """Aim offset [rad] for an enemy crossing at ``v_lat`` (relative, + = rightwards)."""
        return sugeno1(V_LAT, self.lead_consequents, v_lat)

    @staticmethod
    def turn(error: float) -> float:
        return sugeno1(ERROR, TURN, error)

    @staticmethod
    def fire(abs_error: float, distance: float) -> float:
        return sugeno2(AIM, DIST, FIRE, abs_error, distance)

    @staticmethod
    def advance(distance: float, abs_error: float) -> float:
        return sugeno2(ALIGN, DIST, ADVANCE, abs_error, distance)

    @staticmethod
    def strafe(distance: float, abs_error: float) -> float:
        return sugeno2(ALIGN, DIST, STRAFE, abs_error, distance)

    def __call__(self, error: float, omega: float, distance: float) -> AttackOutput:
        """All outputs for an aim error (lead and noise already in it), our turn rate
        [rad/s] and the distance."""
        ae = abs(error)
        return AttackOutput(rotate=self.turn(error - PREDICT * omega), advance=self.advance(distance, ae),
                            strafe_size=self.strafe(distance, ae), fire=self.fire(ae, distance))
