"""The attack controller's rule bases: partitions of unity, monotone outputs."""

import math

import numpy as np
import pytest

from tanktool.sim.agents.fuzzy import (
    AIM, ALIGN, DIST, ERROR, FIRE_THRESHOLD, V_LAT, AttackController, Variable, sugeno1, sugeno2,
)

CTL = AttackController(shell_speed=200.0)
ERRORS = np.linspace(-math.pi, math.pi, 181)
ABS = np.linspace(0.0, math.pi, 121)
DISTS = np.linspace(0.0, 150.0, 121)


@pytest.mark.parametrize("var", [V_LAT, ERROR, AIM, ALIGN, DIST], ids=lambda v: v.name)
def test_terms_are_a_partition_of_unity(var):
    lo, hi = var.peaks[0] - 5.0, var.peaks[-1] + 5.0
    for x in np.linspace(lo, hi, 301):
        m = var.memberships(float(x))
        assert sum(m) == pytest.approx(1.0) and all(0.0 <= v <= 1.0 for v in m)
    for term, p in zip(var.terms, var.peaks):
        assert var.membership(term, p) == 1.0


def test_bad_variables_are_refused():
    with pytest.raises(ValueError, match="increase"):
        Variable("x", ("a", "b"), (1.0, 1.0))
    with pytest.raises(ValueError, match="as many terms"):
        Variable("x", ("a",), (1.0, 2.0))


def nondecreasing(v):
    return bool(np.all(np.diff(v) >= -1e-12))


def test_turn_rises_with_the_angle_error_and_is_symmetric():
    turn = np.array([CTL.turn(float(e)) for e in ERRORS])
    assert nondecreasing(turn)
    assert turn[0] == -1.0 and turn[-1] == 1.0 and CTL.turn(0.0) == 0.0
    assert np.allclose(turn, -turn[::-1])


def test_lead_rises_with_lateral_speed_and_matches_the_intercept_angle():
    v = np.linspace(-20, 20, 81)
    lead = np.array([CTL.lead(float(x)) for x in v])
    assert nondecreasing(lead) and np.allclose(lead, -lead[::-1])
    for s in (2.0, 5.0, 10.0):   # within the rule range the lead is the intercept angle, to 1 %
        assert CTL.lead(s) == pytest.approx(math.asin(s / 200.0), rel=0.01)


@pytest.mark.parametrize("d", [5.0, 20.0, 45.0, 70.0, 120.0])
def test_fire_falls_with_the_angle_error(d):
    assert not nondecreasing([0, 1]) or nondecreasing([-CTL.fire(float(a), d) for a in ABS])
    assert CTL.fire(0.0, d) >= FIRE_THRESHOLD and CTL.fire(0.2, d) == 0.0


@pytest.mark.parametrize("a", [0.0, 0.02, 0.05, 0.2])
def test_fire_falls_with_distance(a):
    assert nondecreasing([-CTL.fire(a, float(d)) for d in DISTS])


def test_fire_tolerance_narrows_with_distance():
    """The largest error still fired at shrinks as the target gets farther (it looks smaller)."""
    def tolerance(d):
        return max(float(a) for a in np.linspace(0, 0.2, 2001) if CTL.fire(float(a), d) >= FIRE_THRESHOLD)
    tol = [tolerance(d) for d in (10.0, 30.0, 60.0, 90.0)]
    assert tol == sorted(tol, reverse=True) and tol[0] > tol[-1]


@pytest.mark.parametrize("a", [0.0, 0.3, 0.6, 1.5])
def test_advance_rises_with_distance(a):
    adv = [CTL.advance(float(d), a) for d in DISTS]
    assert nondecreasing(adv)
    assert adv[0] < 0.0 and adv[-1] > 0.0       # back off when near, close in when far


@pytest.mark.parametrize("d", [5.0, 30.0, 60.0, 100.0])
def test_strafe_falls_with_distance_and_error(d):
    assert nondecreasing([-CTL.strafe(d, float(a)) for a in ABS])
    assert nondecreasing([-CTL.strafe(float(x), 0.1) for x in DISTS])


def test_sugeno_is_interpolation_of_the_consequents():
    v = Variable("x", ("lo", "hi"), (0.0, 10.0))
    assert sugeno1(v, (2.0, 4.0), 2.5) == pytest.approx(2.5)
    w = Variable("y", ("lo", "hi"), (0.0, 1.0))
    assert sugeno2(v, w, ((0.0, 1.0), (10.0, 11.0)), 5.0, 0.5) == pytest.approx(5.5)


def test_controller_outputs_for_a_target_straight_ahead():
    out = CTL(0.0, 0.0, 40.0)
    assert out.rotate == 0.0 and out.fire >= FIRE_THRESHOLD
    # turning already: the predicted error makes it ease off (damping)
    assert CTL(0.2, 1.0, 40.0).rotate < CTL(0.2, 0.0, 40.0).rotate
