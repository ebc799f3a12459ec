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


def correct_walls(t: Tank, contacts: list[tuple[float, float, float, float, float]]) -> None:
    """Move a tank out of the walls it overlaps; ``contacts`` holds the deepest contact
    per wall, deepest first.

    One wall: along its normal.  Two or more: if getting out of the deepest also gets
    out of the second, that is enough; otherwise the translation d that satisfies both
    n1·d = depth1 and n2·d = depth2 (the corner's vertex), so a tank wedged in an acute
    corner comes out in one pass instead of bouncing between the walls.
    """
    if not contacts:
        return
    _, _, n1x, n1z, d1 = contacts[0]
    d1 -= SLOP
    if d1 <= 0.0:
        return
    dx, dz = n1x * d1, n1z * d1
    for _, _, n2x, n2z, d2 in contacts[1:2]:
        d2 -= SLOP
        if d2 <= 0.0 or n2x * dx + n2z * dz >= d2:
            break
        det = n1x * n2z - n1z * n2x
        if abs(det) < 0.05:          # nearly parallel walls: the deepest decides
            break
        vx = (d1 * n2z - n1z * d2) / det
        vz = (n1x * d2 - n2x * d1) / det
        # a vertex far away means walls that almost face each other: do not jump
        if vx * vx + vz * vz <= (8.0 * max(d1, d2)) ** 2:
            dx, dz = vx, vz
    t.x += dx
    t.z += dz
