"""Collision resolution (the 2002 simulator's stage 7, §3.4.4.4).

An impulse j·n changes velocities at once.  With restitution e, the relative normal
velocity at the contact point after the impulse is −e times the one before,

    v2·n = −e v1·n,

which, with both bodies' masses and moments of inertia, gives the paper's

    j = −(1 + e) v1·n / (1/m_A + 1/m_B + (r_A × n)² / I_A + (r_B × n)² / I_B)

where r is the arm from a body's centre of mass to the contact point and
r × n = r_x n_z − r_z n_x (the y component of the 3D cross product, the sign
convention in which θ grows from +x towards +z).  A wall has infinite mass: its
terms vanish.  The impulse is applied only when the contact approaches (v1·n < 0),
the paper's rule, so an impulse never adds kinetic energy:
ΔKE = j (v1·n + v2·n)/2 = j v1·n (1 − e)/2 <= 0.

Positional correction moves bodies out of overlap without touching velocities, so it
neither adds energy nor changes momentum.
"""

from __future__ import annotations

from .body import Tank

#: overlap left in place so resting contacts stay detected and do not jitter [m]
SLOP = 1e-4


def wall_impulse(t: Tank, px: float, pz: float, nx: float, nz: float, e: float) -> float:
    """Apply the wall impulse at contact (px, pz) with normal n (into the tank's side).

    Returns j (0 when the contact is separating or at rest)."""
    rx, rz = px - t.x, pz - t.z
    vx = t.vx - t.omega * rz
    vz = t.vz + t.omega * rx
    vn = vx * nx + vz * nz
    if vn >= 0.0:
        return 0.0
    rn = rx * nz - rz * nx
    m, inertia = t.spec.mass, t.spec.inertia
    j = -(1.0 + e) * vn / (1.0 / m + rn * rn / inertia)
    t.vx += j * nx / m
    t.vz += j * nz / m
    t.omega += rn * j / inertia
    return j


def pair_impulse(a: Tank, b: Tank, px: float, pz: float, nx: float, nz: float, e: float) -> float:
    """Apply the two-body impulse (+j n to a, −j n to b); returns j (0 if separating)."""
    rax, raz = px - a.x, pz - a.z
    rbx, rbz = px - b.x, pz - b.z
    vx = (a.vx - a.omega * raz) - (b.vx - b.omega * rbz)
    vz = (a.vz + a.omega * rax) - (b.vz + b.omega * rbx)
    vn = vx * nx + vz * nz
    if vn >= 0.0:
        return 0.0
    ran = rax * nz - raz * nx
    rbn = rbx * nz - rbz * nx
    ma, mb, ia, ib = a.spec.mass, b.spec.mass, a.spec.inertia, b.spec.inertia
    j = -(1.0 + e) * vn / (1.0 / ma + 1.0 / mb + ran * ran / ia + rbn * rbn / ib)
    a.vx += j * nx / ma
    a.vz += j * nz / ma
    a.omega += ran * j / ia
    b.vx -= j * nx / mb
    b.vz -= j * nz / mb
    b.omega -= rbn * j / ib
    return j


def push_out_of_wall(t: Tank, nx: float, nz: float, depth: float) -> None:
    """Translate the tank along n so the contact sits SLOP short of the wall."""
    d = depth - SLOP
    if d > 0.0:
        t.x += nx * d
        t.z += nz * d


def separate_pair(a: Tank, b: Tank, nx: float, nz: float, depth: float) -> None:
    """Move two overlapping tanks apart along n, shared in inverse proportion to mass
    (the centre of mass of the pair stays put, so momentum bookkeeping is untouched)."""
    d = depth - SLOP
    if d <= 0.0:
        return
    wa = 1.0 / a.spec.mass
    wb = 1.0 / b.spec.mass
    fa = d * wa / (wa + wb)
    fb = d - fa
    a.x += nx * fa
    a.z += nz * fa
    b.x -= nx * fb
    b.z -= nz * fb
