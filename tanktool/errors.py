"""Exception hierarchy.  Every error meant for a user derives from TanktoolError;
the CLI prints its message on one line and exits with status 2 (bad input)."""


class TanktoolError(Exception):
    """Base class of every error the user should see as one clear line."""

    exit_code = 2


class FormatError(TanktoolError):
    """A file could not be parsed: the message names the file and the place."""


class OutputError(TanktoolError):
    """A file or folder could not be written (permissions, a full disk, a file size
    limit, a folder that is not a bundle and must not be replaced, ...)."""


class ArenaError(TanktoolError):
    """An arena cannot be built or used (no floor, no free space, ...)."""


class VehicleError(TanktoolError):
    """A vehicle cannot be built or used."""


class NetError(TanktoolError):
    """A network session failed (bad address, refused join, ...)."""
