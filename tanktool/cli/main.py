"""The ``tanktool`` command group.

Commands live in one module each and are imported only when invoked, so that
``tanktool --help`` stays instant.  Errors derived from TanktoolError become one
line on stderr and exit status 2 (``-v`` shows the traceback).  ``-v`` and ``-q``
work anywhere on the line: before the sub-command (the group's options) or after
it (every command gets the same two options, see :func:`_add_output_options`).
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import re
import sys
import traceback

import click

from .. import __version__
from ..errors import TanktoolError

#: command name -> (module, function, one-line help shown by ``tanktool --help``)
COMMANDS = {
    "import-arena": ("tanktool.cli.import_arena", "import_arena", "Turn an arena model into an arena bundle (walls, spawns, preview)."),
    "import-vehicle": ("tanktool.cli.import_vehicle", "import_vehicle", "Turn a vehicle model into a vehicle bundle (hull points, sphere tree, mass)."),
    "build-navgrid": ("tanktool.cli.build_navgrid", "build_navgrid", "Build an arena's wall quadtree and AI navigation grid, and plot them."),
    "check": ("tanktool.cli.check", "check", "Validate arena and vehicle bundles like a linter."),
    "play": ("tanktool.cli.play", "play", "Play a match (window, or --headless for scripted matches)."),
    "tournament": ("tanktool.cli.tournament", "tournament", "Play bots against each other: round robin, Elo, replays; local cores or Ray."),
}


class UserError(click.ClickException):
    """A TanktoolError shown as one line: ``error: <file>:<place>: <what>``."""

    def __init__(self, message: str, exit_code: int = 2) -> None:
        super().__init__(message)
        self.exit_code = exit_code

    def show(self, file=None) -> None:
        # one line, whatever the message: a library's text may hold line breaks
        click.echo(f"error: {' '.join(self.format_message().split())}", err=True)


class OneLineUsageError(click.UsageError):
    """click's usage error (a bad option value, an unknown option or command) in the
    same one-line form as every other error: ``error: <what> (see `<command> --help`)``,
    exit status 2.  click's own form is four lines (usage, hint, blank, message)."""

    def show(self, file=None) -> None:
        where = f" (see `{self.ctx.command_path} --help`)" if self.ctx is not None else ""
        click.echo(f"error: {' '.join(self.format_message().split())}{where}", err=True)


#: click's "no arguments: show the help" (a UsageError since click 8.2): help, not an error
_HELP = getattr(click.exceptions, "NoArgsIsHelpError", ())


def _one_line(e: click.UsageError) -> OneLineUsageError:
    one = OneLineUsageError(e.format_message(), e.ctx)
    one.exit_code = e.exit_code
    return one


def _set_output(ctx: click.Context, verbose: int, quiet: bool) -> None:
    """Record -v/-q in the root context's dict (where :func:`is_quiet` and the error
    handler look) and set the logging level from them."""
    root = ctx.find_root()
    root.ensure_object(dict)
    obj = root.obj
    obj["verbose"] = obj.get("verbose", 0) + verbose
    obj["quiet"] = bool(obj.get("quiet", False) or quiet)
    v, q = obj["verbose"], obj["quiet"]
    level = logging.ERROR if q else (logging.DEBUG if v > 1 else logging.INFO if v else logging.WARNING)
    logging.basicConfig(level=level, format="%(message)s")
    logging.getLogger().setLevel(level)


def _verbose_cb(ctx: click.Context, param: click.Parameter, value: int) -> None:
    if value:
        _set_output(ctx, value, False)


def _quiet_cb(ctx: click.Context, param: click.Parameter, value: bool) -> None:
    if value:
        _set_output(ctx, 0, True)


def _add_output_options(cmd: click.Command) -> click.Command:
    """Give a sub-command the group's -v/-q (once): ``tanktool check -q x`` then means
    the same as ``tanktool -q check x``.  They are eager so that they take effect
    before any other option's callback runs."""
    names = {o for p in cmd.params for o in getattr(p, "opts", [])}
    if "-v" not in names and "--verbose" not in names:
        cmd.params.append(click.Option(["-v", "--verbose"], count=True, expose_value=False, is_eager=True,
                                       callback=_verbose_cb, help="More output; tracebacks on errors."))
    if "-q" not in names and "--quiet" not in names:
        cmd.params.append(click.Option(["-q", "--quiet"], is_flag=True, expose_value=False, is_eager=True,
                                       callback=_quiet_cb, help="Only errors; no progress bars."))
    return cmd


class LazyGroup(click.Group):
    def make_context(self, info_name, args, parent=None, **extra) -> click.Context:
        try:  # the group's own options (``tanktool --bogus``)
            return super().make_context(info_name, args, parent=parent, **extra)
        except (OneLineUsageError, _HELP):
            raise
        except click.UsageError as e:
            raise _one_line(e) from e

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except (OneLineUsageError, _HELP):
            raise
        except click.UsageError as e:  # a sub-command's options, or no such command
            raise _one_line(e) from e
        except TanktoolError as e:
            if ctx.obj and ctx.obj.get("verbose"):
                traceback.print_exc()
            raise UserError(str(e), e.exit_code) from e
        except OSError as e:  # the system refused: a full disk, a file size limit, a read-only folder
            if ctx.obj and ctx.obj.get("verbose"):
                traceback.print_exc()
            from ..formats.bundle import os_error_text

            if e.errno is None and e.filename is None:
                # a library's OSError (PIL's "broken data stream ..."), not the system's
                raise UserError(f"cannot read a file: {' '.join(str(e).split())[:200] or type(e).__name__}") from e
            where, e.filename = e.filename, None
            raise UserError(f"{where or 'the system'}: {os_error_text(e)}") from e

    def list_commands(self, ctx: click.Context) -> list[str]:
        return [name for name in COMMANDS if self._available(name)]

    @staticmethod
    def _available(name: str) -> bool:
        return importlib.util.find_spec(COMMANDS[name][0]) is not None

    def get_command(self, ctx: click.Context, name: str):
        if name not in COMMANDS or not self._available(name):
            return None
        module, attr, _ = COMMANDS[name]
        return _add_output_options(getattr(importlib.import_module(module), attr))

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, COMMANDS[name][2]) for name in self.list_commands(ctx)]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="tanktool")
@click.option("-v", "--verbose", count=True, help="More output; tracebacks on errors.")
@click.option("-q", "--quiet", is_flag=True, help="Only errors; no progress bars.")
@click.pass_context
def cli(ctx: click.Context, verbose: int, quiet: bool) -> None:
    """tanktool: arena-authoring pipeline and game for 3D tank combat.

    \b
    Typical flow:
      tanktool import-arena arena.3ds -o arenas/mine
      tanktool import-vehicle tank.3ds -o vehicles/mytank
      tanktool build-navgrid arenas/mine
      tanktool check arenas vehicles
      tanktool play --arena arenas/mine
    """
    ctx.ensure_object(dict)
    ctx.obj["verbose"] = 0
    ctx.obj["quiet"] = False
    _set_output(ctx, verbose, quiet)


def is_quiet() -> bool:
    ctx = click.get_current_context(silent=True)
    while ctx is not None:
        if ctx.obj and "quiet" in ctx.obj:
            return bool(ctx.obj["quiet"])
        ctx = ctx.parent
    return False


def echo(message: str) -> None:
    """Print an informational line unless ``-q`` was given."""
    if not is_quiet():
        click.echo(message)


def _wants_verbose(args: list[str]) -> bool:
    """-v anywhere on the line (before a ``--`` that ends the options)."""
    for a in args:
        if a == "--":
            return False
        if a == "--verbose" or re.fullmatch(r"-v+", a):
            return True
    return False


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point: click's own handling plus a short line for bugs."""
    from ..memory import keep_freed_memory

    keep_freed_memory()  # numpy's large temporaries reused, not faulted in again (tanktool/memory.py)
    args = sys.argv[1:] if argv is None else argv
    try:
        cli.main(args=args, prog_name="tanktool")
    except SystemExit:
        raise
    except Exception as e:  # a bug, not bad input: say so briefly unless -v
        if _wants_verbose(args):
            traceback.print_exc()
        else:
            click.echo(f"internal error: {type(e).__name__}: {e} (run with -v for the traceback)", err=True)
        sys.exit(3)


if __name__ == "__main__":
    main()
