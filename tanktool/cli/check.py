"""``tanktool check PATH...``: validate arenas, vehicles and wall lists like a linter.

Prints ``PATH:LINE: CODE severity: message (hint)`` lines and a summary, or with
``--json`` one document.  Exit 0 clean, 1 errors (or warnings with ``--strict``),
2 when a path cannot be read.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click


@click.command("check")
@click.argument("paths", nargs=-1, type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Write one JSON document instead of text lines.")
@click.option("--strict", is_flag=True, help="Exit 1 on warnings too.")
@click.option("--rules", "list_rules", is_flag=True, help="List every rule code and exit.")
def check(paths: tuple[Path, ...], as_json: bool, strict: bool, list_rules: bool) -> None:
    """Validate arena bundles, vehicle bundles, walls.txt files, or folders of them
    (no PATH: tanktool's bundled arenas and vehicles).

    Arenas are measured against the vehicles named with them or beside them
    (X/vehicles/ for X/arenas/NAME), else against the bundled vehicles, and the
    output says so; vehicles likewise against arenas.

    \b
    Examples:
      tanktool check arenas vehicles
      tanktool check --strict --json arenas/yard
      tanktool check --strict                      (the bundled content)
    """
    from ..check import RULES, run_check
    from .main import is_quiet

    if list_rules:
        for r in RULES.values():
            click.echo(f"{r.code}  {r.severity:<7}  {r.title}")
        return
    notes = []
    if not paths:
        from ..content import bundled_dir

        paths = tuple(p for p in (bundled_dir("arenas"), bundled_dir("vehicles")) if p is not None)
        if not paths:
            raise click.UsageError("no PATH given and no bundled content found: give at least one PATH "
                                   "(an arena, a vehicle, a walls.txt or a folder)")
        notes.append(f"note: no PATH given: checking the bundled content ({', '.join(map(str, paths))})")
    report = run_check(list(paths))
    report.notes[:0] = notes
    for msg in report.unreadable:
        click.echo(f"error: {msg}", err=True)
    if as_json:
        click.echo(json.dumps(report.to_dict(), indent=2))
    else:
        for d in report.diagnostics:
            if d.severity == "error" or not is_quiet():
                click.echo(d.format())
        if not is_quiet():
            for note in report.notes:
                click.echo(note)
        click.echo(report.summary())
    sys.exit(report.exit_code(strict))
