"""Options shared by several commands, defined once and stacked as decorators."""

from __future__ import annotations

import io
from pathlib import Path

import click

up_option = click.option(
    "--up", type=click.Choice(["y", "z"]), default=None,
    help="Up axis of the model file (default: z for .3ds, y for everything else).",
)
scale_option = click.option(
    "--scale", type=click.FloatRange(min=0, min_open=True, max=1e6), default=1.0, show_default=True,
    help="Multiply the model's coordinates (after the axis conversion) to get metres.",
)
force_option = click.option("--force", is_flag=True, help="Overwrite an existing bundle.")
out_option = click.option(
    "-o", "--out", type=click.Path(path_type=Path), default=None, help="Bundle folder to write (default: ./<name>).",
)
name_option = click.option("--name", default=None, help="Bundle name (default: the model's file stem).")


def progress(iterable=None, length: int | None = None, label: str = "", **kw):
    """A click progress bar that stays silent under ``-q`` and when not on a terminal."""
    from .main import is_quiet

    hidden = is_quiet()
    return click.progressbar(iterable, length=length, label=label, file=io.StringIO() if hidden else None, **kw)
