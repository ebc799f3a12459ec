"""The world and its step: the seven stages of the 2002 simulator (§3.4.5).

``World.step(dt, commands)`` reads like Box2D's world step, one named function per
stage of the paper:

1. initialise objects   — clear forces, tick reload timers, respawn the dead
2. direction            — commands become each tank's intent
3. forces               — engine, strafe, turn torque, rolling friction, lateral grip; guns fire
4. integration          — semi-implicit Euler (default) or the paper's explicit Euler
5. vertices             — headings to (cos, sin), wall candidates from the wall index
6. collision detection  — hull points vs walls, sphere trees vs each other, shells swept
7. collision resolution — impulses, positional correction, and back to 6 until
                          nothing collides (bounded); damage, kills

and returns the step's events.  The match's rules (``sim.rules.Rules``: the gun,
spawn protection, where tanks spawn, the time and score limits) are the world's;
once a limit is reached ``World.match.over`` is set and the world stops stepping.
Everything random comes from the world's own seeded
``random.Random``; tanks, pairs and shells are visited in index order, so the same
seed and the same commands give bit-identical results.
"""

from __future__ import annotations

import math
import random
from typing import Any, Sequence

import numpy as np

from ..errors import ArenaError
from .body import Tank, TankSpec
from ..nav.quadtree import WallQuadtree
from .collide import QuadtreeIndex, WallIndex, WallSet, shell_hits_tank, tank_contact, wall_contacts
from .commands import Command
from .events import EVENT_KINDS, Event  # noqa: F401  (re-exported: callers import them from here)
from .flat_ground import FlatGround
from .resolve import SLOP, correct_walls, pair_impulse, separate_pair, wall_impulse
from .rules import DEFAULT as DEFAULT_RULES, GRAVITY, MatchState, Rules
from .weapons import Shell, fire, fly, stop_fraction
from .on_ground import slope_pull
from .world_ground import EYE, GroundMixin  # noqa: F401

DT = 1.0 / 120.0
INTEGRATORS = ("semi-implicit", "euler")
#: a wall contact after this long without one counts as a new bump [s]
BUMP_GAP = 0.25
TWO_PI = 2.0 * math.pi
#: the engine's pull fades from full to nothing over the last 1/FADE of the top speed
FADE = 20.0


class World(GroundMixin):
    """Tanks, shells and walls, stepped at a fixed rate.

    Parameters
    ----------
    walls : a ``WallList`` (its walls and auxiliary rectangle are used) or (n, 2, 2) segments
    specs : one TankSpec per tank
    spawns : (k, 3) spawn points ``[x, z, heading]``, k >= len(specs)
    seed : seeds the world's random generator (initial spawn order, respawn choice)
    dt : default step length [s]
    integrator : "semi-implicit" (default) or "euler"
    bounds : (2, 2) arena bounds (default: the wall list's); when the wall list has no
             auxiliary rectangle, this rectangle is added as walls
    wall_index : the wall quadtree (``nav.quadtree.WallQuadtree``, built here by default
                 with leaves of about 12 m, or ``quadtree_depth``) or any object with
                 exact ``query_point`` and ``query_segment``
    ground : the arena's ground: a ``sim.ground.Ground`` (relief, several levels) or a
             ``sim.flat_ground.FlatGround`` (a flat one-floor arena, the 2002
             simulation; the default, at y = 0).  Tanks stand on its surface (height,
             pitch and roll from it, gravity along its slopes), move between levels
             along its links and never leave it, collide with the walls of their own
             level only, and shells and sight meet the model's triangles (a flat
             ground has none of these: the walls alone stop tanks, shells and sight).
    rules : the match's rules (``sim.rules.Rules``; default ``sim.rules.DEFAULT``).
            Every tank's spec is armed with the rules' gun (``Rules.arm``), so
            ``tank.spec.shell_speed`` is the speed its shells leave at.

    ``match`` (a ``sim.rules.MatchState``) says whether the match is over, why and
    who won; ``protection_left(i)`` the seconds of spawn protection tank i has left.
    """

    def __init__(self, walls: Any, specs: Sequence[TankSpec], spawns: Any, *, seed: int = 0,
                 dt: float = DT, integrator: str = "semi-implicit", wall_index: WallIndex | None = None,
                 names: Sequence[str] | None = None, respawn_delay: float = 3.0,
                 max_iterations: int = 8, wall_slack: float = 2.0, quadtree_depth: int | None = None,
                 bounds: Any = None, ground: Any = None, rules: Rules | None = None) -> None:
        if integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {INTEGRATORS}, got {integrator!r}")
        if not (dt > 0 and math.isfinite(dt)):
            raise ValueError(f"dt must be a positive number of seconds, got {dt}")
        if hasattr(walls, "all_segments"):
            segments = walls.all_segments()
            has_aux = getattr(walls, "aux", None) is not None
            wb = np.asarray(walls.bounds, dtype=np.float64)
        else:
            segments = np.asarray(walls, dtype=np.float64).reshape(-1, 2, 2)
            has_aux = False
            pts = segments.reshape(-1, 2)
            wb = np.array([pts.min(axis=0), pts.max(axis=0)]) if len(pts) else np.zeros((2, 2))
        self.bounds = wb if bounds is None else np.asarray(bounds, dtype=np.float64).reshape(2, 2)
        if not has_aux and bounds is not None:
            # nothing may leave the arena: its bounding rectangle becomes four more walls
            (x0, z0), (x1, z1) = self.bounds.tolist()
            rect = np.array([[[x0, z0], [x1, z0]], [[x1, z0], [x1, z1]], [[x1, z1], [x0, z1]], [[x0, z1], [x0, z0]]])
            segments = np.concatenate([segments.reshape(-1, 2, 2), rect])
        if wall_index is None:
            span = float(np.max(self.bounds[1] - self.bounds[0])) if len(segments) else 1.0
            depth = quadtree_depth if quadtree_depth is not None else int(min(max(round(math.log2(max(span, 1.0) / 12.0)), 2), 6))
            wall_index = WallQuadtree.build(segments, self.bounds, depth=depth)
        if hasattr(wall_index, "child") and hasattr(wall_index, "box"):
            wall_index = QuadtreeIndex(wall_index)   # same buckets, plain-Python lookups
        self.walls = WallSet(segments, wall_index)
        self.ground = ground if ground else FlatGround(self.bounds)
        sp = np.asarray(spawns, dtype=np.float64)
        sp = sp.reshape(len(sp), -1) if sp.size else np.zeros((0, 3))
        self.spawns = [tuple(float(v) for v in row[:3]) for row in sp]
        # the height of the surface under each spawn (which level it stands on), if given
        self.spawn_y = [float(row[3]) if len(row) > 3 and math.isfinite(row[3]) else None for row in sp]
        self.level_walls: list[WallSet] = []
        self._wall_y: list[list[tuple[float, float]]] = []
        if self.ground.relief:  # a flat ground's walls stop every tank: one set
            self._build_level_walls(walls, segments)
        if len(self.spawns) < len(specs):   # more tanks than spawn points: free places of the ground too
            from .extra_spawns import extend

            big = max(specs, key=lambda s: s.radius)
            extend(self, len(specs), big.radius, big.box[2] - big.box[0], big.name)
        self.seed = int(seed)
        self.rng = random.Random(self.seed)
        self.dt = float(dt)
        self.integrator = integrator
        self.respawn_delay = float(respawn_delay)
        self.max_iterations = int(max_iterations)
        self.wall_slack = float(wall_slack)
        self.rules = DEFAULT_RULES if rules is None else rules
        self.match = MatchState(self.rules.time_limit, self.rules.score_limit)
        order = list(range(len(self.spawns)))
        self.rng.shuffle(order)
        if self.rules.hidden_spawns:
            order = self._hidden_order(order, len(specs))
        armed: dict[int, TankSpec] = {}
        self.tanks: list[Tank] = []
        for i, spec in enumerate(specs):
            x, z, h = self.spawns[order[i]]
            gun = armed.setdefault(id(spec), self.rules.arm(spec))
            t = Tank(i, gun, 0.0, 0.0, h, name=names[i] if names else None)
            t.place(x, z, h)
            self.stand(t, self.spawn_y[order[i]])
            self.tanks.append(t)
        #: simulated time until which each tank is under spawn protection
        self.protected_until = [self.rules.spawn_protection] * len(self.tanks)
        self.shells: list[Shell] = []
        self.t = 0.0
        self.steps = 0
        self.iterations_used = 0          # resolution passes in the last step (for tests/bench)
        #: the events of the last step (what drivers perceive from: ``sim.bots``)
        self.events: list[Event] = []
        self._reach = [_sphere_reach(s) for s in specs]

    # ------------------------------------------------------------------ public
    def step(self, dt: float | None = None, commands: Sequence[Command | None] = ()) -> list[Event]:
        """Advance the world by ``dt`` (the world's fixed dt when None); return the events."""
        dt = self.dt if dt is None else float(dt)
        if len(commands) > len(self.tanks):
            raise ValueError(f"{len(commands)} commands for {len(self.tanks)} tanks")
        if self.match.over:
            self.events = []
            return []
        events: list[Event] = []
        self.events = events
        self.steps += 1
        self.t += dt
        self._step_dt = dt
        self.initialise_objects(dt, events)
        self.direction(commands)
        self.forces(dt, events)
        self.integrate(dt)
        self.vertices()
        collisions = self.detect_collisions(range(len(self.tanks)), with_shells=True)
        before = [(t.x, t.z) for t in self.tanks]
        self.resolve_collisions(collisions, events)
        self.ground.contain(self.tanks, before, self._tilt)
        if self.match.check(self) is not None:
            w = self.match.winner
            x, z = (self.tanks[w].x, self.tanks[w].z) if w is not None else (0.0, 0.0)
            events.append(Event(self.steps, self.t, "match_end", -1 if w is None else w, x, z))
        return events

    def protection_left(self, index: int) -> float:
        """Seconds of spawn protection tank ``index`` has left (0: none; it ends
        when the tank fires)."""
        t = self.tanks[index]
        return max(self.protected_until[index] - self.t, 0.0) if t.alive else 0.0

    @property
    def names(self) -> list[str]:
        return [t.name for t in self.tanks]

    def state(self) -> tuple:
        """Every number that evolves, for determinism checks and snapshots."""
        return (self.steps, self.t,
                tuple((t.x, t.z, t.heading, t.vx, t.vz, t.omega, t.hp, t.alive, t.reload, t.y, t.level)
                      for t in self.tanks),
                tuple((s.owner, s.x, s.y, s.z, s.vx, s.vy, s.vz) for s in self.shells))

    _TANK_FIELDS = ("x", "z", "heading", "vx", "vz", "omega", "hp", "alive", "respawn_at", "reload",
                    "kills", "deaths", "shots", "hits", "wall_bumps", "distance", "touching_wall",
                    "y", "level", "pitch", "roll")

    def snapshot(self) -> dict[str, Any]:
        """Everything needed to continue this world exactly (plain data: for network
        peers taking over a session, replays, tests)."""
        m = self.match
        return {
            "t": self.t, "steps": self.steps, "rng": self.rng.getstate(),
            "tanks": [{f: getattr(t, f) for f in self._TANK_FIELDS} for t in self.tanks],
            "shells": [{f: getattr(s, f) for f in Shell.__slots__} for s in self.shells],
            "protected_until": list(self.protected_until),
            "match": {"over": m.over, "reason": m.reason, "ended_at": m.ended_at, "winner": m.winner},
        }

    def restore(self, snap: dict[str, Any]) -> None:
        """Return to a :meth:`snapshot` of a world with the same walls and tanks."""
        if len(snap["tanks"]) != len(self.tanks):
            raise ValueError(f"snapshot has {len(snap['tanks'])} tanks, this world {len(self.tanks)}")
        self.t, self.steps = snap["t"], snap["steps"]
        self.rng.setstate(snap["rng"])
        for t, d in zip(self.tanks, snap["tanks"]):
            for f in self._TANK_FIELDS:
                if f in d:  # snapshots from before tanks had heights lack the last four
                    setattr(t, f, d[f])
            t.c, t.s = math.cos(t.heading), math.sin(t.heading)
            t.wall_cache = None
        self.shells = []
        for d in snap["shells"]:
            sh = Shell.__new__(Shell)
            for f in Shell.__slots__:
                setattr(sh, f, d[f])
            self.shells.append(sh)
        self.protected_until = list(snap.get("protected_until", [0.0] * len(self.tanks)))
        m = snap.get("match")
        if m is not None:
            self.match.over, self.match.reason = m["over"], m["reason"]
            self.match.ended_at, self.match.winner = m["ended_at"], m["winner"]

    def momentum(self) -> tuple[float, float]:
        """Total linear momentum of the live tanks [kg m/s]."""
        return (sum(t.spec.mass * t.vx for t in self.tanks if t.alive),
                sum(t.spec.mass * t.vz for t in self.tanks if t.alive))

    def kinetic_energy(self) -> float:
        return sum(t.kinetic_energy() for t in self.tanks if t.alive)

    # ------------------------------------------------------------------ 1
    def initialise_objects(self, dt: float, events: list[Event]) -> None:
        """Clear forces, tick reload timers, bring back tanks whose respawn time came."""
        for t in self.tanks:
            t.fx = t.fz = t.torque = 0.0
            if t.reload > 0.0:
                t.reload = max(t.reload - dt, 0.0)
            if not t.alive and self.t >= t.respawn_at:
                self._respawn(t, events)

    # ------------------------------------------------------------------ 2
    def direction(self, commands: Sequence[Command | None]) -> None:
        """Commands become intents; the dead and the silent get none."""
        for i, t in enumerate(self.tanks):
            cmd = commands[i] if i < len(commands) else None
            t.intent = cmd.to_tuple() if (cmd is not None and t.alive) else (0.0, 0.0, 0.0, False)

    # ------------------------------------------------------------------ 3
    def forces(self, dt: float, events: list[Event]) -> None:
        """Forces and torque on each tank, in its own frame then turned to the world.

        Forward:  F_f = E·a·fade − m·μ·v_f          (μ: rolling drag rate [1/s])
        Sideways: F_r = S·s·fade − m·μ·v_r − m·g·slide
        Turning:  τ   = T·r − (T/ω_max)·ω
        ``fade`` = 20·(1 − (speed in the commanded direction)/(top speed)) clamped to
        [0, 1]: full pull up to 95 % of top speed, nothing at it (half of it sideways), so
        top speed is a cap the engine respects, yet a collision may still push a tank
        faster.  Vehicle bundles set E = m·μ·top_speed, where drag alone would level
        off at top speed.  ``slide`` is the part of the sideways velocity
        outside what the strafe command asks for (all of it when not strafing), and the
        grip rate g (much larger than μ) kills it, so tracks do not slide like ice.
        Drag rates are capped at 1/dt so an explicit step can never reverse a velocity.
        """
        inv_dt = 1.0 / dt
        for t in self.tanks:
            if not t.alive:
                continue
            sp = t.spec
            a, r, s, want_fire = t.intent
            c, sn = t.c, t.s
            vf = t.vx * c + t.vz * sn
            vr = -t.vx * sn + t.vz * c
            m = sp.mass
            strafe_top = 0.5 * sp.top_speed
            ff = -m * min(sp.friction, inv_dt) * vf
            if a != 0.0:
                fade = FADE * (1.0 - (vf if a > 0.0 else -vf) / sp.top_speed)
                ff += sp.engine_force * a * (0.0 if fade < 0.0 else 1.0 if fade > 1.0 else fade)
            # lateral: rolling drag inside the commanded strafe range, grip beyond it
            fr = -m * min(sp.friction, inv_dt) * vr
            lo, hi = (0.0, s * strafe_top) if s >= 0.0 else (s * strafe_top, 0.0)
            slide = vr - (lo if vr < lo else hi if vr > hi else vr)
            fr -= m * min(sp.grip, inv_dt) * slide
            if s != 0.0:
                fade = FADE * (1.0 - (vr if s > 0.0 else -vr) / strafe_top)
                fr += sp.strafe_force * s * (0.0 if fade < 0.0 else 1.0 if fade > 1.0 else fade)
            t.fx = ff * c - fr * sn
            t.fz = ff * sn + fr * c
            if t.pitch != 0.0 or t.roll != 0.0:
                # gravity along the slope, but for what the tracks hold (on_ground.slope_pull)
                px, pz = slope_pull(t, m, a, s, vf, vr)
                t.fx += px
                t.fz += pz
            turn_drag = min(sp.turn_drag, sp.inertia * inv_dt)
            t.torque = sp.turn_torque * r - turn_drag * t.omega
            if want_fire and t.reload <= 0.0:
                shell = fire(t, self.walls, self.rules, self.rng, self.ground)
                self.shells.append(shell)
                self.protected_until[t.index] = -math.inf      # firing ends spawn protection
                t.reload = sp.fire_interval
                t.shots += 1
                events.append(Event(self.steps, self.t, "shot", t.index, t.x, t.z))

    # ------------------------------------------------------------------ 4
    def integrate(self, dt: float) -> None:
        """Euler steps.  Semi-implicit: v += a dt, then x += v dt (stable for the drag
        terms); explicit (the paper's): x += v dt with the old v, then v += a dt."""
        explicit = self.integrator == "euler"
        for t in self.tanks:
            if not t.alive:
                continue
            m, inertia = t.spec.mass, t.spec.inertia
            ax, az, alpha = t.fx / m, t.fz / m, t.torque / inertia
            if explicit:
                dx, dz, dh = t.vx * dt, t.vz * dt, t.omega * dt
                t.vx += ax * dt
                t.vz += az * dt
                t.omega += alpha * dt
            else:
                t.vx += ax * dt
                t.vz += az * dt
                t.omega += alpha * dt
                dx, dz, dh = t.vx * dt, t.vz * dt, t.omega * dt
            dx, dz = self.ground.keep_move(t, dx, dz)
            t.x += dx
            t.z += dz
            h = t.heading + dh
            if h > math.pi or h <= -math.pi:
                h = math.remainder(h, TWO_PI)
            t.heading = h
            t.distance += math.sqrt(dx * dx + dz * dz)
        for s in self.shells:
            fly(s, dt)

    # ------------------------------------------------------------------ 5
    def vertices(self) -> None:
        """Heading to (cos, sin) for every point transform of the step; refresh each
        tank's wall candidates from the wall index once it has moved ``wall_slack``
        from where they were fetched (walls within radius + slack of that place
        include every wall within radius of the tank now)."""
        slack = self.wall_slack
        for t in self.tanks:
            if not t.alive:
                continue
            t.c, t.s = math.cos(t.heading), math.sin(t.heading)
            self._tilt(t)
            wc = t.wall_cache
            if wc is None or (t.x - wc[0]) ** 2 + (t.z - wc[1]) ** 2 > slack * slack or wc[3] != t.level:
                t.wall_cache = self._wall_candidates(t, slack)

    # ------------------------------------------------------------------ 6
    def detect_collisions(self, which: Any, with_shells: bool = False) -> "Collisions":
        """Contacts of the tanks in ``which`` (with walls and with any other tank) and,
        when asked, where this step's shells stop."""
        tanks = self.tanks
        which = sorted(set(which))
        wset = set(which)
        walls: list[tuple[int, list]] = []
        for i in which:
            t = tanks[i]
            if not t.alive:
                continue
            wc = t.wall_cache
            if wc is None or (t.x - wc[0]) ** 2 + (t.z - wc[1]) ** 2 > self.wall_slack ** 2 or wc[3] != t.level:
                t.wall_cache = wc = self._wall_candidates(t, self.wall_slack)
            cand = wc[2]
            if cand:
                found = wall_contacts(t, self.walls_of(t), cand)
                if found:
                    walls.append((i, found))
        pairs: list[tuple[int, int, tuple]] = []
        reach = self._reach
        n = len(tanks)
        for i in range(n):
            a = tanks[i]
            if not a.alive:
                continue
            for j in range(i + 1, n):
                if i not in wset and j not in wset:
                    continue
                b = tanks[j]
                if not b.alive:
                    continue
                dx, dz = a.x - b.x, a.z - b.z
                rr = reach[i] + reach[j]
                if dx * dx + dz * dz > rr * rr:
                    continue
                if a.y + a.spec.height < b.y or b.y + b.spec.height < a.y:
                    continue  # one on a bridge, one under it
                c = tank_contact(a, b)
                if c is not None:
                    pairs.append((i, j, c))
        shells: list[tuple[Shell, int, float, str]] = []
        if with_shells:
            for s in self.shells:
                f, what = stop_fraction(s, getattr(self, "_step_dt", self.dt))
                victim = -1
                sx, sz = 0.5 * (s.px + s.x), 0.5 * (s.pz + s.z)
                half = 0.5 * math.hypot(s.x - s.px, s.z - s.pz)
                for t in tanks:
                    if not t.alive or t.index == s.owner:
                        continue
                    rr = reach[t.index] + half
                    if (t.x - sx) ** 2 + (t.z - sz) ** 2 > rr * rr:
                        continue
                    h = shell_hits_tank(t, (s.px, s.py, s.pz), (s.x, s.y, s.z))
                    if h is not None and h <= f:
                        f, what, victim = h, "tank", t.index
                if what:
                    shells.append((s, victim, f, what))
        return Collisions(walls, pairs, shells)

    # ------------------------------------------------------------------ 7
    def resolve_collisions(self, col: "Collisions", events: list[Event]) -> None:
        """Impulses and positional correction, then detect again for the tanks that
        were involved, until nothing approaches or overlaps (at most
        ``max_iterations`` passes); then shells do their damage."""
        tanks = self.tanks
        shell_stops = col.shells
        bumped: dict[int, tuple[float, float, float, int]] = {}
        passes = 0
        while (col.walls or col.pairs) and passes < self.max_iterations:
            passes += 1
            involved: set[int] = set()
            for i, j, (px, pz, nx, nz, depth) in col.pairs:
                a, b = tanks[i], tanks[j]
                pair_impulse(a, b, px, pz, nx, nz, min(a.spec.restitution, b.spec.restitution))
                separate_pair(a, b, nx, nz, depth)
                involved.update((i, j))
            # walls last: whatever the pairs did, nothing may end inside a wall
            for i, found in col.walls:
                t = tanks[i]
                e = t.spec.restitution
                jsum = 0.0
                per_wall: dict[int, tuple] = {}
                for contact, k in found:
                    px, pz, nx, nz, depth = contact
                    jsum += wall_impulse(t, px, pz, nx, nz, e)
                    if k not in per_wall or depth > per_wall[k][4]:
                        per_wall[k] = contact
                (px, pz, _, _, _), k = max(((c, k) for k, c in per_wall.items()), key=lambda ck: (ck[0][4], -ck[1]))
                correct_walls(t, sorted(per_wall.values(), key=lambda c: -c[4]))
                # a bump is located where the first impulse of the step happened;
                # its value sums the impulses of every pass
                prev = bumped.get(i)
                if prev is None or (prev[2] == 0.0 and jsum > 0.0):
                    bumped[i] = (px, pz, (prev[2] if prev else 0.0) + jsum, k)
                else:
                    bumped[i] = (prev[0], prev[1], prev[2] + jsum, prev[3])
                involved.add(i)
            col = self.detect_collisions(involved)
            col = col.needing_work(tanks)
        self.iterations_used = passes
        for i in sorted(bumped):
            t = tanks[i]
            px, pz, j, k = bumped[i]
            if j > 0.0 and self.t - t.touching_wall > BUMP_GAP:
                t.wall_bumps += 1
                events.append(Event(self.steps, self.t, "wall_bump", i, px, pz, k, j))
            t.touching_wall = self.t
        if shell_stops or self.shells:
            self._resolve_shells(shell_stops, events)

    # ------------------------------------------------------------------ helpers
    def _resolve_shells(self, stops: list, events: list[Event]) -> None:
        for s, victim, f, what in stops:
            s.alive = False
            if what != "tank":
                continue
            t = self.tanks[victim]
            if not t.alive:
                continue
            shooter = self.tanks[s.owner]
            if self.t < self.protected_until[victim]:
                hx, hz = s.px + f * (s.x - s.px), s.pz + f * (s.z - s.pz)
                events.append(Event(self.steps, self.t, "shielded", s.owner, hx, hz, victim, 0.0))
                continue
            hx = s.px + f * (s.x - s.px)
            hz = s.pz + f * (s.z - s.pz)
            shooter.hits += 1
            t.hp -= s.damage
            events.append(Event(self.steps, self.t, "hit", s.owner, hx, hz, victim, s.damage))
            if t.hp <= 0.0:
                t.alive = False
                t.deaths += 1
                t.vx = t.vz = t.omega = 0.0
                t.respawn_at = self.t + self.respawn_delay
                shooter.kills += 1
                events.append(Event(self.steps, self.t, "kill", s.owner, t.x, t.z, victim, 0.0))
        # shells that left the arena's bounds or are dead go
        (x0, z0), (x1, z1) = self.bounds
        self.shells = [s for s in self.shells
                       if s.alive and x0 - 1.0 <= s.x <= x1 + 1.0 and z0 - 1.0 <= s.z <= z1 + 1.0]

    def _respawn(self, t: Tank, events: list[Event]) -> None:
        """Back at a free spawn point (no live tank within both radii + 1 m), chosen with
        the world's generator; if none is free, the one farthest from the live tanks.
        With ``rules.hidden_spawns`` the choice is among the free points no live enemy
        has a line of sight to, if any; else among those seen by the fewest."""
        live = [o for o in self.tanks if o.alive and o is not t]
        free, best, best_d = [], None, -1.0
        for k, (x, z, h) in enumerate(self.spawns):
            y = self.spawn_y[k]
            d = min((math.hypot(o.x - x, o.z - z) - o.spec.radius for o in live
                     if y is None or abs(o.y - y) < o.spec.height + t.spec.height), default=math.inf)
            if d > t.spec.radius + 1.0:
                free.append(k)
            if d > best_d:
                best, best_d = k, d
        if free and self.rules.hidden_spawns:
            seen = [self._watchers(k, live) for k in free]
            least = min(seen)
            free = [k for k, n in zip(free, seen) if n == least]
        k = self.rng.choice(free) if free else best
        x, z, h = self.spawns[k]
        t.place(x, z, h)
        self.stand(t, self.spawn_y[k])
        t.hp = t.spec.hit_points
        t.alive = True
        t.reload = 0.0
        self.protected_until[t.index] = self.t + self.rules.spawn_protection
        events.append(Event(self.steps, self.t, "respawn", t.index, x, z))


class Collisions:
    """What stage 6 found: wall contacts per tank, tank pairs, shell stops."""

    __slots__ = ("walls", "pairs", "shells")

    def __init__(self, walls: list, pairs: list, shells: list) -> None:
        self.walls, self.pairs, self.shells = walls, pairs, shells

    def needing_work(self, tanks: list[Tank]) -> "Collisions":
        """Keep the contacts that still approach or overlap beyond the slop; resting
        contacts left at SLOP depth end the loop."""
        def work(t: Tank, c: tuple, other: Tank | None = None) -> bool:
            px, pz, nx, nz, depth = c
            if depth > 2.0 * SLOP:
                return True
            vx, vz = t.point_velocity(px, pz)
            if other is not None:
                ox, oz = other.point_velocity(px, pz)
                vx, vz = vx - ox, vz - oz
            return vx * nx + vz * nz < -1e-9
        walls = [(i, found) for i, found in self.walls if any(work(tanks[i], c) for c, _ in found)]
        pairs = [(i, j, c) for i, j, c in self.pairs if work(tanks[i], c, tanks[j])]
        return Collisions(walls, pairs, self.shells)


def _sphere_reach(spec: TankSpec) -> float:
    """Radius in (x, z) about the centre of mass that holds every sphere of the tree."""
    return max(math.hypot(x, z) + r for x, _, z, r in spec.spheres)
