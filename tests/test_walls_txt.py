import numpy as np
import pytest

from tanktool.errors import FormatError
from tanktool.formats.walls_txt import (
    WallList, aux_rectangle, format_walls, parse_walls, read_walls, write_walls,
)

PAPER = """# X1    Z1     X2     Z2     Direction
0.0     0.0    0.0    200.0   1
0.0     200.0  50.0   200.0  -1
50.0    200.0  50.0   300.0   1
"""


def test_parse_paper_example():
    w = parse_walls(PAPER)
    assert len(w) == 3
    assert w.aux is None
    np.testing.assert_array_equal(w.segments[1], [[0, 200], [50, 200]])
    assert list(w.direction) == [1, -1, 1]
    assert list(w.lines) == [2, 3, 4]
    # n = Direction * (-(Z2-Z1), X2-X1) / length
    np.testing.assert_allclose(w.normals[0], [-1, 0])
    np.testing.assert_allclose(w.normals[1], [0, -1])


def test_round_trip_with_aux(tmp_path):
    w = WallList([[[1, 1], [5, 1]], [[5, 1], [5, 4]]], [1, -1], aux_rectangle(0, 0, 10, 8))
    p = tmp_path / "walls.txt"
    write_walls(p, w, header="test arena")
    text = p.read_text()
    assert "# auxiliary" in text
    back = read_walls(p)
    np.testing.assert_array_equal(back.segments, w.segments)
    np.testing.assert_array_equal(back.aux, w.aux)
    np.testing.assert_array_equal(back.bounds, [[0, 0], [10, 8]])
    # auxiliary normals point inwards
    centre = back.aux.reshape(-1, 2).mean(axis=0)
    from tanktool.formats.walls_txt import aux_direction
    d = WallList(back.aux, aux_direction(back.aux)).normals
    to_c = centre - back.aux[:, 0]
    assert ((d * to_c).sum(axis=1) > 0).all()


def test_aux_without_marker_detected():
    text = "1 1 5 1 1\n0 0 10 0 1\n10 0 10 8 1\n10 8 0 8 1\n0 8 0 0 1\n"
    w = parse_walls(text)
    assert len(w) == 1 and w.aux is not None


def test_last_four_not_rectangle_means_no_aux():
    text = "1 1 5 1 1\n0 0 10 0 1\n10 0 10 8 1\n10 8 0 9 1\n0 8 0 0 1\n"
    assert parse_walls(text).aux is None


@pytest.mark.parametrize("text, where, what", [
    ("0 0 1 1\n", ":1:", "expected 5 fields"),
    ("0 0 1 1 1\n0 0 a 1 1\n", ":2:", "expected numbers"),
    ("0 0 1 nan 1\n", ":1:", "finite"),
    ("0 0 1 1 1\n0 0 -1e308 1 1\n", ":2:", "within 1e+06 m"),
    ("0 0 1 1 2\n", ":1:", "Direction must be +1 or -1"),
    ("0 0 1 1 x\n", ":1:", "Direction must be +1 or -1"),
    ("0 0 1 1 1\n# auxiliary\n0 0 1 0 1\n", "", "expected 4 auxiliary walls"),
    ("20 0 30 1 1\n# auxiliary\n0 0 10 0 1\n10 0 10 8 1\n10 8 0 8 1\n0 8 0 0 1\n", ":3:", "enclosing"),
])
def test_bad_input_names_place(text, where, what):
    with pytest.raises(FormatError) as e:
        parse_walls(text, "arena/walls.txt")
    assert f"arena/walls.txt{where}" in str(e.value)
    assert what in str(e.value)


def test_read_missing_and_binary(tmp_path):
    with pytest.raises(FormatError, match="no such file"):
        read_walls(tmp_path / "nope.txt")
    p = tmp_path / "bin.txt"
    p.write_bytes(b"0 0 1 1 1\n\xff\xfe")
    with pytest.raises(FormatError, match=r"bin.txt:2: not UTF-8"):
        read_walls(p)


def test_format_is_plain_numbers():
    w = WallList([[[0.5, -0.0], [2, 3.25]]], [-1])
    line = format_walls(w).splitlines()[-1]
    assert line == "0.5 0 2 3.25 -1"
