import subprocess
import sys

from click.testing import CliRunner

from tanktool import __version__
from tanktool.cli.main import cli


def test_version():
    r = CliRunner().invoke(cli, ["--version"])
    assert r.exit_code == 0
    assert __version__ in r.output


def test_help_lists_commands():
    r = CliRunner().invoke(cli, ["--help"])
    assert r.exit_code == 0
    for name in ("import-arena", "import-vehicle", "build-navgrid", "check", "play"):
        from tanktool.cli.main import LazyGroup
        if LazyGroup._available(name):
            assert name in r.output


def test_unknown_command_is_usage_error():
    r = CliRunner().invoke(cli, ["no-such-command"])
    assert r.exit_code == 2


def test_console_script_runs():
    out = subprocess.run([sys.executable, "-m", "tanktool", "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and __version__ in out.stdout
