"""B205: the textures a bundle's manifest lists ([model] textures) are images inside
the bundle, of a size the game keeps (docs/check.md, docs/formats.md "Textures")."""

from __future__ import annotations

import os
import shutil
import struct
import zlib
from pathlib import Path

import pytest

from tanktool.check import run_check
from tanktool.content import bundled_dir


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _png(w: int, h: int) -> bytes:
    """A valid PNG of w x h black pixels (built by hand: any declared size)."""
    rows = zlib.compress(b"".join(b"\x00" + bytes(3 * w) for _ in range(h)))
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + _chunk(b"IDAT", rows) + _chunk(b"IEND", b""))


def _huge_png_header(w: int, h: int) -> bytes:
    """A PNG that declares w x h pixels and holds no pixel data (a 'bomb' by header)."""
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + _chunk(b"IEND", b"")


@pytest.fixture
def box(tmp_path: Path) -> Path:
    b = tmp_path / "arenas" / "box"
    shutil.copytree(bundled_dir("arenas") / "box", b)
    return b


def _set_textures(bundle: Path, names: list[str]) -> None:
    toml = bundle / "arena.toml"
    text = toml.read_text()
    start = text.index("textures = [")
    end = text.index("]", start) + 1
    toml.write_text(text[:start] + "textures = [" + ", ".join(f'"{n}"' for n in names) + "]" + text[end:])


def _b205(bundle: Path) -> list[str]:
    report = run_check([bundle])
    return [d.message for d in report.diagnostics if d.code == "B205"], report


def test_the_bundled_textures_pass(box):
    msgs, report = _b205(box)
    assert msgs == [] and report.exit_code(strict=True) == 0, [d.format() for d in report.diagnostics]


@pytest.mark.parametrize("name, make, says", [
    ("textures/gone.png", None, "is missing"),
    ("../outside.png", "outside", "outside the bundle"),
    ("/etc/passwd", None, "outside the bundle"),
    ("textures/zero.png", "link-dev-zero", "outside the bundle"),
    ("textures/notes.txt", "text", "is not an image file"),
    ("textures/fake.png", "garbage", "not a readable image"),
    ("textures/cut.png", "truncated", "not a readable image"),
    ("textures/big.png", "huge", "too large: 5000 x 5000 pixels"),
    ("textures", None, "not a regular file"),
])
def test_a_bad_texture_is_b205_at_the_textures_line(box, name, make, says):
    target = box / name
    if make == "outside":
        (box.parent / "outside.png").write_bytes(_png(4, 4))
    elif make == "link-dev-zero":
        os.symlink("/dev/zero", target)
    elif make == "text":
        target.write_text("not a picture\n")
    elif make == "garbage":
        target.write_bytes(b"\x89PNG" + bytes(range(256)) * 4)
    elif make == "truncated":
        target.write_bytes(_png(64, 64)[:60])
    elif make == "huge":
        target.write_bytes(_huge_png_header(5000, 5000))
    _set_textures(box, ["textures/brick.png", name])
    msgs, report = _b205(box)
    assert len(msgs) == 1 and says in msgs[0] and repr(name) in msgs[0], msgs
    d = next(d for d in report.diagnostics if d.code == "B205")
    assert d.line == next(i for i, ln in enumerate((box / "arena.toml").read_text().splitlines(), 1)
                          if ln.startswith("textures ="))
    assert report.exit_code() == 1


def test_a_texture_list_of_the_wrong_type_is_b102(box):
    toml = box / "arena.toml"
    text = toml.read_text()
    start = text.index("textures = [")
    toml.write_text(text[:start] + "textures = 7" + text[text.index("]", start) + 1:])
    report = run_check([box])
    assert any(d.code == "B102" and "textures" in d.message for d in report.diagnostics)
    assert not any(d.code in ("B205", "X001") for d in report.diagnostics)


def test_a_4096_texture_is_not_too_large(box):
    (box / "textures" / "max.png").write_bytes(_png(4096, 4096))
    _set_textures(box, ["textures/max.png"])
    assert _b205(box)[0] == []


def test_a_vehicle_texture_is_checked_the_same_way(tmp_path):
    """vehicle.toml's [model] textures go through the same bundle file rules (the whole
    vehicle check also drives it through every bundled arena: slower, not needed here)."""
    from tanktool.check.manifest import Manifest, file_rules

    v = tmp_path / "vehicles" / "light"
    shutil.copytree(bundled_dir("vehicles") / "light", v)
    assert file_rules(Manifest(v / "vehicle.toml"), v, ("hull.txt", "spheres.txt")) == []
    (v / "textures" / "steel.png").unlink()
    out = file_rules(Manifest(v / "vehicle.toml"), v, ("hull.txt", "spheres.txt"))
    assert [(d.code, d.message) for d in out] == [("B205", "texture 'textures/steel.png' is missing")]
