import pytest

from tanktool.errors import FormatError, OutputError
from tanktool.formats.bundle import atomic_write_text, read_toml, sha256_file, write_toml
from tanktool.formats.bundle_swap import staged_dir


def test_toml_round_trip(tmp_path):
    p = tmp_path / "a.toml"
    write_toml(p, {"name": "box", "bounds": [[0.0, 0.0], [1.0, 2.0]]})
    assert read_toml(p) == {"name": "box", "bounds": [[0.0, 0.0], [1.0, 2.0]]}
    assert len(sha256_file(p)) == 64


def test_bad_toml_names_file(tmp_path):
    p = tmp_path / "arena.toml"
    p.write_text("name = \n")
    with pytest.raises(FormatError, match="arena.toml: invalid TOML"):
        read_toml(p)


def test_staged_dir_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "bundle"
    with pytest.raises(RuntimeError):
        with staged_dir(target) as d:
            atomic_write_text(d / "x.txt", "half")
            raise RuntimeError("boom")
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []


def test_staged_dir_refuses_then_forces(tmp_path):
    target = tmp_path / "bundle"
    with staged_dir(target, manifest="arena.toml") as d:
        (d / "arena.toml").write_text('tool_version = "test"\n')
        (d / "walls.txt").write_text("1")
    with pytest.raises(OutputError, match="--force"):
        with staged_dir(target, manifest="arena.toml"):
            pass
    with staged_dir(target, force=True, manifest="arena.toml") as d:
        (d / "arena.toml").write_text('tool_version = "test"\n')
        (d / "b").write_text("2")
    assert sorted(p.name for p in target.iterdir()) == ["arena.toml", "b"]
    assert [p.name for p in tmp_path.iterdir()] == ["bundle"]
