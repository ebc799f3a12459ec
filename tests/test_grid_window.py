"""One lattice for a bundle's layered grid (nav/grid_window.py): import-arena's grid
comes from the surface it analysed, build-navgrid's from model.glb, and the two are
one grid by construction -- also on a model off the cell's multiples whose vertices
float32 rounds."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.nav.grid_window import crop, crop_links, grid_window, model_lattice

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402


def test_the_model_lattice_snaps_the_low_corner_down_to_a_multiple_of_the_cell():
    v = np.array([[-3.2, 0.0, 1.1], [7.9, 2.0, 4.0]])
    origin, shape = model_lattice(v, 0.5)
    assert origin.tolist() == [-3.5, 1.0] and shape == (6, 23)   # to 8.0 and 4.0
    origin, shape = model_lattice(np.array([[-2.0, 0, 3.0], [2.0, 1, 5.0]]), 0.5)
    assert origin.tolist() == [-2.0, 3.0] and shape == (4, 8)    # on the lattice: kept


def test_the_window_holds_every_column_over_the_bounds_even_past_the_lattice():
    w = grid_window(np.array([-3.5, 1.0]), 0.5, np.array([[-1.2, 1.0], [2.0, 9.3]]))
    assert (w.i0, w.j0, w.nz, w.nx) == (0, 4, 17, 7) and w.origin.tolist() == [-1.5, 1.0]
    layers = np.arange(2 * 6 * 23).reshape(2, 6, 23)
    cut = crop(layers, w, -1)
    assert cut.shape == (2, 17, 7)
    assert np.array_equal(cut[:, :6], layers[:, :, 4:11]) and (cut[:, 6:] == -1).all()
    links = np.zeros((1, 6, 23, 4), dtype=np.int8)
    cut = crop_links(links, w)
    assert (cut[0, :, -1, 0] == -1).all() and (cut[0, :, 0, 2] == -1).all() and (cut[0, 0, :, 3] == -1).all()
    assert (cut[0, 1:5, 1:6] == 0).all()


@pytest.mark.parametrize("name", ["bridge"])
def test_import_and_build_navgrid_give_one_grid_off_the_lattice(tmp_path, name):
    m = make_levels.level(name)
    # off every multiple of the cell, and coordinates float32 rounds (model.glb stores float32)
    m.apply_translation([0.1234567891, 0.0, -0.3333333333])
    src = tmp_path / f"{name}.obj"
    m.export(src)
    out = tmp_path / name
    res = CliRunner().invoke(cli, ["-q", "import-arena", str(src), "-o", str(out)])
    assert res.exit_code == 0, res.output
    grids = sorted(p.name for p in out.glob("navgrid*.npz"))
    before = {f: (out / f).read_bytes() for f in grids}
    res = CliRunner().invoke(cli, ["-q", "build-navgrid", str(out)])
    assert res.exit_code == 0, res.output
    for f, data in before.items():
        assert (out / f).read_bytes() == data, f
    from tanktool.nav.navgrid import NavGrid

    g = NavGrid.load(out / "navgrid.npz")
    assert g.levels == 2 and abs(g.origin[0] / 0.5 - round(g.origin[0] / 0.5)) < 1e-9


def test_the_import_rounds_the_model_as_model_glb_stores_it():
    import trimesh

    from tanktool.importer import _as_stored

    m = trimesh.Trimesh([[0.1, 0.0, 0.3], [1.1, 0.0, 0.3], [0.1, 0.0, 1.7]], [[0, 1, 2]], process=False)
    assert not np.array_equal(m.vertices, m.vertices.astype(np.float32))
    _as_stored(m)
    assert m.vertices.dtype == np.float64 and np.array_equal(m.vertices, m.vertices.astype(np.float32))
