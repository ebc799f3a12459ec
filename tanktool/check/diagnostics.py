"""Diagnostics: what ``tanktool check`` reports, and the stable table of rule codes.

A code never changes meaning once published, so scripts and CI configurations can
rely on it: new rules get new codes, retired codes are not reused.  Codes are grouped
by what they look at: ``A1xx`` walls.txt syntax, ``A2xx`` wall geometry, ``A3xx``
free space and spawn points, ``B`` bundle files (arena and vehicle alike), ``V``
vehicles, ``X`` the checker itself.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

ERROR = "error"
WARNING = "warning"


@dataclass(frozen=True)
class Rule:
    code: str
    severity: str
    title: str
    hint: str


#: every rule: code -> (severity, one-line meaning, default fix hint)
RULES: dict[str, Rule] = {r.code: r for r in [
    # walls.txt syntax
    Rule("A101", ERROR, "a walls.txt line cannot be parsed", "write 5 fields per line: X1 Z1 X2 Z2 Direction"),
    Rule("A102", ERROR, "a wall coordinate is NaN, infinite or beyond 1,000 km", "replace it with a finite number of metres"),
    Rule("A103", ERROR, "a wall's Direction is not +1 or -1", "use 1 or -1 to pick the side its normal points to"),
    Rule("A104", ERROR, "the auxiliary walls are missing or not four", "end the file with '# auxiliary' and the 4 walls of the bounding rectangle"),
    Rule("A105", ERROR, "the auxiliary walls do not form an axis-aligned rectangle enclosing every wall", "make the 4 auxiliary walls the bounding rectangle of all walls (plus a margin)"),
    # wall geometry
    Rule("A201", ERROR, "a wall has zero length", "delete the wall or give its ends different coordinates"),
    Rule("A202", ERROR, "two walls are the same (same ends, same free side)", "delete one of the two"),
    Rule("A203", ERROR, "two walls overlap along their length", "merge them into one wall or split them where they meet"),
    Rule("A204", ERROR, "two walls cross each other (an X, not a T)", "split both walls at the crossing, or move one"),
    Rule("A205", ERROR, "a wall's normal points into solid material instead of free space", "flip the wall's Direction (1 <-> -1)"),
    # free space and spawn points
    Rule("A301", ERROR, "the free space holding the spawn points is not closed (a leak)", "close the gap with a wall so no tank can drive out"),
    Rule("A302", ERROR, "a spawn point is inside solid material or outside the arena's walls", "move the spawn point into the arena's free space"),
    Rule("A303", ERROR, "a spawn point is too close to a wall for the largest vehicle", "move the spawn point away from the wall"),
    Rule("A304", ERROR, "a spawn point cannot be reached from the others", "open a passage wide enough for the largest vehicle, or move the spawn"),
    Rule("A305", WARNING, "fewer than 8 spawn points", "add spawn points: matches need up to 8 tanks"),
    Rule("A306", WARNING, "a passage is narrower than the largest bundled vehicle", "widen the passage or accept that big tanks cannot use it"),
    Rule("A307", WARNING, "free space that cannot be reached from the spawn points (an island)", "connect it, fill it in, or flip its walls if it is meant to be solid"),
    Rule("A308", WARNING, "the floor is not flat", "flatten the model's floor: vehicles drive on the plane floor_y"),
    Rule("A309", ERROR, "the navigation grid has no node a tank can use", "make room for the largest vehicle, or rebuild the grid (build-navgrid) with its clearance"),
    Rule("A310", WARNING, "a level of the navigation grid cannot be reached from the spawn points", "join it with a ramp or steps within the climb, or remove it"),
    Rule("A311", WARNING, "a spawn point stands on a small island of the navigation grid", "move the spawn point onto the main part of the arena"),
    Rule("A312", ERROR, "the walkable surface was found for less headroom than a vehicle is tall", "re-import the arena with --headroom at least the tallest vehicle's height"),
    Rule("A313", WARNING, "the ground under a spawn point is uneven", "move the spawn point to level ground"),
    Rule("A314", ERROR, "a spawn point is on no node of the navigation grid", "move the spawn point onto the walkable surface, clear of the walls"),
    Rule("A315", ERROR, "a spawn point cannot be reached from the others over the navigation grid", "join the parts with a ramp, or move the spawn point"),
    # bundle files
    Rule("B101", ERROR, "the bundle's manifest (arena.toml / vehicle.toml) cannot be read", "fix the TOML syntax, or rebuild the bundle"),
    Rule("B102", ERROR, "a manifest key is missing or has the wrong type", "add the key with a value of the right type, or rebuild the bundle"),
    Rule("B201", ERROR, "a model file named by the manifest is missing", "restore the file, or rebuild the bundle from its source model"),
    Rule("B202", ERROR, "a derived file is missing", "rebuild the bundle's derived files"),
    Rule("B203", ERROR, "a derived file is stale (its sha256 does not match the manifest)", "rebuild the bundle's derived files"),
    Rule("B204", ERROR, "the source model changed since the bundle was built", "rebuild the bundle from the new source model"),
    Rule("B205", ERROR, "a texture listed in [model] textures is missing, outside the bundle, not an image or too large", "restore the image (at most 4096 x 4096 pixels) inside the bundle, or rebuild the bundle"),
    Rule("B301", ERROR, "play cannot load the bundle (a value or file it needs is unusable)", "fix the key or file the message names, or rebuild the bundle"),
    # vehicles
    Rule("V101", ERROR, "a hull.txt line cannot be parsed", "write one 'x y z' point per line"),
    Rule("V102", ERROR, "the hull has fewer than 8 or more than 16 points", "rebuild the hull with 8 to 16 points (--hull-points)"),
    Rule("V103", ERROR, "a vertex of the model lies outside the hull", "rebuild the hull from the current model"),
    Rule("V104", ERROR, "the centre of mass lies outside the hull", "fix [mass] centre_of_mass, or rebuild the bundle"),
    Rule("V105", ERROR, "the vehicle lies on its side or stands on end (taller than it is wide)", "re-import it with the model file's up axis (--up y or --up z)"),
    Rule("V106", WARNING, "the vehicle is wider across than it is long: it may face sideways", "re-import it with the model file's front axis (--forward)"),
    Rule("V107", WARNING, "the vehicle's size is outside what real vehicles have (1 to 15 m long)", "re-import it with the --scale that turns the model's units into metres"),
    Rule("V201", ERROR, "a spheres.txt line cannot be parsed or breaks the tree's structure", "write 'id parent level cx cy cz r', root first, parents before children"),
    Rule("V202", ERROR, "the sphere tree is not conservative: part of the model's surface is in no leaf sphere", "rebuild the sphere tree from the current model"),
    Rule("V203", ERROR, "a parent sphere does not enclose its children's parts of the model", "grow the parent sphere, or rebuild the sphere tree"),
    Rule("V301", ERROR, "mass or moment of inertia is not positive", "set a positive mass (kg) and inertia (kg m^2)"),
    Rule("V302", ERROR, "a drive parameter is physically impossible", "set it inside the range the message gives"),
    Rule("V303", WARNING, "a drive parameter is outside the range real tanks have", "check the value and its unit"),
    Rule("V401", WARNING, "the vehicle does not fit through a passage of a bundled arena", "make the vehicle smaller or widen the arena's passage"),
    # the checker itself
    Rule("X001", ERROR, "a rule failed on this input (a bug in tanktool check)", "report it with the file that triggers it"),
]}


@dataclass
class Diagnostic:
    """One finding: ``path:line: code severity: message (hint)``.

    ``line`` is 1-based; 0 means the file as a whole.
    """

    path: str
    line: int
    code: str
    severity: str
    message: str
    hint: str

    def format(self) -> str:
        where = f"{self.path}:{self.line}" if self.line > 0 else self.path
        return f"{where}: {self.code} {self.severity}: {self.message} ({self.hint})"

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def diag(code: str, path: str, line: int, message: str, hint: str | None = None) -> Diagnostic:
    """A diagnostic with the severity and (unless given) the hint of rule ``code``."""
    rule = RULES[code]
    return Diagnostic(str(path), int(line), code, rule.severity, message, hint or rule.hint)


def fmt_xz(p) -> str:
    """A point of the (x, z) plane as people read it in messages."""
    return f"({float(p[0]):.2f}, {float(p[1]):.2f})"
