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


def test_verbose_and_quiet_work_anywhere_on_the_line(tmp_path):
    # every internal error says "run with -v": -v must work after the sub-command too
    missing = str(tmp_path / "nope.obj")
    for args in (["-v", "import-arena", missing], ["import-arena", missing, "-v"],
                 ["import-arena", "--verbose", missing]):
        r = CliRunner().invoke(cli, args)
        assert r.exit_code == 2, args
        assert "Traceback" in r.output and "error: " in r.output, args
    r = CliRunner().invoke(cli, ["import-arena", missing])
    assert r.exit_code == 2 and "Traceback" not in r.output
    # -q after the sub-command keeps only errors, as before it
    corpus = "tests/data/broken/A305_few_spawns"
    loud = CliRunner().invoke(cli, ["check", corpus])
    for args in (["-q", "check", corpus], ["check", corpus, "-q"], ["check", "--quiet", corpus]):
        r = CliRunner().invoke(cli, args)
        assert r.exit_code == 0, (args, r.output)
        assert "A305" in loud.output and "A305" not in r.output, args
        assert "1 warning" in r.output
    # both are listed in every command's help
    r = CliRunner().invoke(cli, ["play", "--help"])
    assert "-v, --verbose" in r.output and "-q, --quiet" in r.output


def test_internal_error_traceback_with_v_after_the_command(monkeypatch, capsys):
    from tanktool.cli import main as main_mod

    def boom(*a, **k):
        raise RuntimeError("a bug")

    monkeypatch.setattr("tanktool.check.run_check", boom)
    import pytest

    with pytest.raises(SystemExit) as e:
        main_mod.main(["check", "x", "-v"])
    assert e.value.code == 3
    err = capsys.readouterr().err
    assert "Traceback" in err and "RuntimeError: a bug" in err
    with pytest.raises(SystemExit) as e:
        main_mod.main(["check", "x"])
    err = capsys.readouterr().err
    assert e.value.code == 3 and "Traceback" not in err and "run with -v" in err
