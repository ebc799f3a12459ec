/* tanktool._kernels: the walkable-surface loops numpy cannot make fast, in C.
 *
 * Six files (the rasteriser in _kernels_raster.c, the faces' normals in _kernels_faces.c,
 * the grid's loops in _kernels_grid.c, the open spans' passes in _kernels_surface.c,
 * the ground under a tank in _kernels_ground.c, shared definitions in _kernels.h).
 * Optional: setup.py builds it when a C compiler is there; tanktool/nav/kernels.py
 * falls back to numpy otherwise, with identical results (tests/test_kernels.py
 * compares the two).  No numpy headers: arrays come in through the buffer protocol
 * (C-contiguous, the dtypes kernels.py makes sure of), so building needs only
 * Python's own headers.
 *
 *   link_spans(col, floor, ceil, start, nz, nx, headroom, climb, out)
 *       col, start: int64; floor, ceil: int64 or both int32 (a surface's: not widened,
 *       ~45 ms a call on hix); out: int32 (n, 4), filled in place (n < 2**31)
 *   chamfer(link, dist, limit)
 *       link: int32 (n, 4); dist: int32 (n,), the starting values, relaxed in place
 *   chamfer_near(link, dist, limit, col, nx, ncols)   (_kernels_surface.c)
 *       as chamfer, over links between neighbour columns only (col: int64 (n,) sorted)
 *   reach(link, dist)
 *       as chamfer, straight steps of 2 only (surface_report._distance_from)
 *   filters(col, smin, smax, walk, nz, nx, headroom, climb, w3, lifted, ledge, steep, low)
 *       int64 spans, bool walk; the five bool outputs of span_filters.filter_masks
 *   components(link, label)
 *       link: int32 (n, 4); label: int64 (n,) written: the smallest span of each component
 *   walkable_faces(X, Y, Z, f0, f1, f2, cos_slope, flat_ny, walk, flat) -> ok   (_kernels_faces.c)
 *   flat_faces(X, Y, Z, f0, f1, f2, up_min2, flat_ny, height, area) -> k   (_kernels_faces.c)
 *   raster_merge(tri, abc, steep, walk, flat, nz, nx, ch, max_steps, row_lo, row_hi, thr)
 *       -> (pieces, col, smin, smax, walk, flat, top_walk)   (_kernels_raster.c)
 *       the pieces of every triangle (of rows row_lo .. row_hi - 1 only): steep ones by
 *       their exact sections (heightfield._cells_exact), gentle ones by their planes
 *       (_cells_plane); merged as heightfield._merge does; the spans as bytearrays
 *       (int64 col, smin, smax; bool flags).  tri: float64 (n, 9) x0 x1 x2 z0 z1 z2
 *       y0 y1 y2 in grid units (y in metres); abc: float64 (n, 3) the plane
 *       y = A + B x + C z of each gentle triangle; steep, walk, flat: bool (n,)
 *   grid_labels(valid, link, L, nz, nx, out) -> k   (_kernels_grid.c)
 *   grid_links(span_of, link, level, col, exists, per, out)   (_kernels_grid.c)
 *   grid_runs(valid, link, L, nz, nx, row_index, row_total, col_index, col_total)   (_kernels_grid.c)
 *   open_spans(col, smin, smax, walk, out_col, out_floor, out_ceil) -> m   (_kernels_surface.c)
 *   snap_heights(floor, walk, flat, heights, origin_y, ch, out)   (_kernels_surface.c)
 *   flat_floor_of(flat_cells, span_of, span_y, flat_h, cell_h, out_idx, out_pos)   (_kernels_surface.c)
 *   scatter_layers(level, col, height, clear, per, exists, height_out, span_out, clear_out)
 *       (_kernels_surface.c)
 *   level_votes(col, keep, link, level, rounds)   (_kernels_surface.c)
 *   lift_portals(col, level, link, steps)   (_kernels_surface.c)
 *   ground_tilt(h, flat, L, nz, nx, ox, oz, cell, climb, reach, level, x, z, c, s, hl, hw)   (_kernels_ground.c)
 *   ground_height(h, L, nz, nx, ox, oz, cell, climb, level, x, z), ground_follow(link, L, nz, nx, level,
 *       i0, j0, i1, j1), grid_walk(link, ok, rows, cols, out, L, nz, nx, k), grade_cut(link, heights,
 *       L, NZ, NX, most), solid_visible(solid, points, out, nz, nx, ny, ox, oz, y0, cs, ch, margin,
 *       step, max_range)   (_kernels_ground.c)
 *   astar_layered(valid, link, L, nz, nx, start, goal) -> [flat node, ...]   (_kernels_path.c)
 *
 * Built with -ffp-contract=off: no fused multiply-adds, so the floating-point results
 * are those of numpy's one operation at a time.
 */
#include "_kernels.h"

/* the four directions +x, +z, -x, -z as (di, dj), as heightfield.neighbour_columns */
static const int DI[4] = {0, 1, 0, -1};
static const int DJ[4] = {1, 0, -1, 0};

/* element k of an int64 (w) or int32 array */
static inline i64 rd(const void *a, i64 k, int w) { return w ? ((const i64 *)a)[k] : ((const int32_t *)a)[k]; }

static PyObject *link_spans(PyObject *self, PyObject *args) {
    Py_buffer col, floor_, ceil_, start, out;
    i64 nz, nx, headroom, climb;
    if (!PyArg_ParseTuple(args, "y*y*y*y*LLLLw*", &col, &floor_, &ceil_, &start, &nz, &nx, &headroom, &climb,
                          &out))
        return NULL;
    Py_ssize_t n = col.len / 8;
    PyObject *ret = NULL;
    const int w = floor_.len == 8 * n && n > 0;   /* int64 floors and ceilings, else int32 */
    if (!need(&floor_, n, w ? 8 : 4, "floor") || !need(&ceil_, n, w ? 8 : 4, "ceil") ||
        !need(&start, nz * nx + 1, 8, "start") || !need(&out, 4 * n, 4, "out"))
        goto done;
    if (n >= INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "link_spans: 2**31 spans or more (int32 links)");
        goto done;
    }
    {
        const i64 *c = col.buf, *st = start.buf;
        const void *f = floor_.buf, *ce = ceil_.buf;
        int32_t *o = out.buf;
        Py_BEGIN_ALLOW_THREADS
        i64 last = -1, i = 0, j = 0;
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (c[s] != last) {  /* col sorted: the next column's (i, j) by steps, a division at a gap */
                if (last >= 0 && c[s] - last < nx) {
                    j += c[s] - last;
                    if (j >= nx) { j -= nx; ++i; }
                } else {
                    i = c[s] / nx;
                    j = c[s] - i * nx;
                }
                last = c[s];
            }
            for (int d = 0; d < 4; ++d) {
                const i64 ii = i + DI[d], jj = j + DJ[d];
                i64 found = -1;
                if (ii >= 0 && ii < nz && jj >= 0 && jj < nx) {
                    const i64 nc = ii * nx + jj;
                    for (i64 k = st[nc]; k < st[nc + 1]; ++k) {
                        const i64 gap = min64(rd(ce, s, w), rd(ce, k, w)) - max64(rd(f, s, w), rd(f, k, w));
                        const i64 dy = rd(f, k, w) - rd(f, s, w);
                        if (gap >= headroom && (dy <= climb && -dy <= climb)) {
                            found = k;
                            break;
                        }
                    }
                }
                o[4 * s + d] = (int32_t)found;
            }
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&col);
    PyBuffer_Release(&floor_);
    PyBuffer_Release(&ceil_);
    PyBuffer_Release(&start);
    PyBuffer_Release(&out);
    return ret;
}

#define OPEN ((i64)1 << 15)

/* at() and relax(): _kernels.h (chamfer_near in _kernels_surface.c shares them) */

/* one relaxation of span s over straight links only (2 a step); off the edge is no
 * source here (surface_report._distance_from) */
static inline int32_t relax_straight(const int32_t *L, const int32_t *dist, Py_ssize_t s, int32_t v) {
    for (int d = 0; d < 4; ++d) {
        const int32_t t = L[4 * s + d];
        if (t >= 0 && dist[t] + 2 < v) v = dist[t] + 2;
    }
    return v;
}

typedef int32_t (*relax_fn)(const int32_t *, const int32_t *, Py_ssize_t, int32_t);

/* sweeps forward and back in turn (spans come in scan order, so each sweep carries a
 * distance across the level) until one changes nothing: every span then holds its
 * relaxed value, the numpy relaxation's fixed point (unique: the shortest paths).  A
 * pair of sweeps without a change was asked for, one or two sweeps more. */
static inline void sweep(const int32_t *L, int32_t *D, Py_ssize_t n, relax_fn relax_span) {
    for (int back = 0, changed = 1; changed; back = !back) {
        changed = 0;
        for (Py_ssize_t k = 0; k < n; ++k) {
            const Py_ssize_t s = back ? n - 1 - k : k;
            /* a step costs 2 at least: a span at 2 or less keeps its value (the report's
               sources, most of a level, at 0: hix's straight-step distance 107 -> 48 ms) */
            if (D[s] <= 2) continue;
            const int32_t v = relax_span(L, D, s, D[s]);
            if (v < D[s]) { D[s] = v; changed = 1; }
        }
    }
}

static PyObject *chamfer(PyObject *self, PyObject *args) {
    Py_buffer link, dist;
    int limit;
    if (!PyArg_ParseTuple(args, "y*w*i", &link, &dist, &limit)) return NULL;
    Py_ssize_t n = dist.len / 4;
    PyObject *ret = NULL;
    if (!need(&link, 4 * n, 4, "link")) goto done;
    {
        const int32_t *L = link.buf;
        int32_t *D = dist.buf;
        Py_BEGIN_ALLOW_THREADS
        /* every span at its shortest chamfer path, capped at limit */
        sweep(L, D, n, relax);
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&link);
    PyBuffer_Release(&dist);
    return ret;
}

/* surface_report._distance_from: half cells from the nearest source (dist 0) along
 * straight links only (2 a step), capped at the starting value of the other spans
 * (the limit).  Sweeps forward and back until nothing changes: the numpy
 * relaxation's fixed point, with one int32 a span where it took seven. */
static PyObject *reach(PyObject *self, PyObject *args) {
    Py_buffer link, dist;
    if (!PyArg_ParseTuple(args, "y*w*", &link, &dist)) return NULL;
    Py_ssize_t n = dist.len / 4;
    PyObject *ret = NULL;
    if (!need(&link, 4 * n, 4, "link")) goto done;
    {
        const int32_t *L = link.buf;
        int32_t *D = dist.buf;
        Py_BEGIN_ALLOW_THREADS
        sweep(L, D, n, relax_straight);
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&link);
    PyBuffer_Release(&dist);
    return ret;
}

/* ------------------------------------------------------------------ components */

static inline i64 find_root(i64 *parent, i64 a) {
    while (parent[a] != a) {
        parent[a] = parent[parent[a]];  /* path halving */
        a = parent[a];
    }
    return a;
}

/* walkable.components: each span's label is the smallest span index of its component
 * over the links (either way).  Union-find, the larger root always hung under the
 * smaller, so a root is its set's smallest index: the labels need no second pass. */
static PyObject *components(PyObject *self, PyObject *args) {
    Py_buffer link, label;
    if (!PyArg_ParseTuple(args, "y*w*", &link, &label)) return NULL;
    const Py_ssize_t n = label.len / 8;
    PyObject *ret = NULL;
    if (!need(&link, 4 * n, 4, "link")) goto done;
    {
        const int32_t *L = link.buf;
        i64 *P = label.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0; s < n; ++s) P[s] = s;
        for (Py_ssize_t s = 0; s < n; ++s)
            for (int d = 0; d < 4; ++d) {
                const i64 t = L[4 * s + d];
                if (t < 0) continue;
                i64 a = find_root(P, s), b = find_root(P, t);
                if (a == b) continue;
                if (a < b) P[b] = a; else P[a] = b;
            }
        for (Py_ssize_t s = 0; s < n; ++s) P[s] = find_root(P, s);
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&link);
    PyBuffer_Release(&label);
    return ret;
}

/* ------------------------------------------------------------------ the three filters */

/* span_filters.filter_masks in one pass per filter: low hanging obstacles lifted,
 * ledges and steep spans (every floor of the four neighbour columns), too little headroom.  col, smin,
 * smax: int64 spans sorted by (column, bottom); walk: bool; the five outputs bool. */
static PyObject *filters(PyObject *self, PyObject *args) {
    Py_buffer col, smin, smax, walk, w3, lifted, ledge, steep, low;
    i64 nz, nx, headroom, climb;
    if (!PyArg_ParseTuple(args, "y*y*y*y*LLLLw*w*w*w*w*", &col, &smin, &smax, &walk, &nz, &nx, &headroom, &climb,
                          &w3, &lifted, &ledge, &steep, &low))
        return NULL;
    const Py_ssize_t n = col.len / 8;
    PyObject *ret = NULL;
    i64 *start = NULL, *ceil_ = NULL;
    if (!need(&smin, n, 8, "smin") || !need(&smax, n, 8, "smax") || !need(&walk, n, 1, "walk") ||
        !need(&w3, n, 1, "w3") || !need(&lifted, n, 1, "lifted") || !need(&ledge, n, 1, "ledge") ||
        !need(&steep, n, 1, "steep") || !need(&low, n, 1, "low"))
        goto done;
    start = malloc((nz * nx + 1) * sizeof(i64));
    ceil_ = malloc((n ? n : 1) * sizeof(i64));
    if (!start || !ceil_) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const i64 *C = col.buf, *lo = smin.buf, *hi = smax.buf;
        const char *W = walk.buf;
        char *out = w3.buf, *lif = lifted.buf, *led = ledge.buf, *stp = steep.buf, *lw = low.buf;
        Py_BEGIN_ALLOW_THREADS
        /* column starts and each span's ceiling (the next span's bottom in its column) */
        Py_ssize_t k = 0;
        for (i64 c = 0; c < nz * nx; ++c) {
            start[c] = k;
            while (k < n && C[k] == c) ++k;
        }
        start[nz * nx] = n;
        for (Py_ssize_t i = 0; i < n; ++i) ceil_[i] = (i + 1 < n && C[i + 1] == C[i]) ? lo[i + 1] : OPEN;
        for (Py_ssize_t i = 0; i < n; ++i) {
            /* 1. walkable from the walkable span below (its flag before this pass) */
            int w = W[i] != 0;
            if (!w && i > 0 && W[i - 1] && C[i - 1] == C[i]) {
                const i64 d = hi[i] - hi[i - 1];
                if (d <= climb && -d <= climb) w = 1;
            }
            lif[i] = w && !W[i];
            out[i] = (char)w;
            led[i] = stp[i] = lw[i] = 0;
        }
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (!out[s]) continue;
            /* 2. ledges and steep spans (span_filters._ledge_scan) */
            const i64 i = C[s] / nx, j = C[s] % nx, bs = hi[s], ts = ceil_[s];
            i64 m = OPEN, a0 = bs, a1 = bs;
            for (int d = 0; d < 4; ++d) {
                const i64 ii = i + DI[d], jj = j + DJ[d];
                if (!(ii >= 0 && ii < nz && jj >= 0 && jj < nx)) {
                    m = min64(m, -climb - bs);
                    continue;
                }
                const i64 nc = ii * nx + jj, k0 = start[nc], k1 = start[nc + 1];
                const i64 ntop0 = k1 > k0 ? lo[k0] : OPEN;
                if (min64(ts, ntop0) - max64(bs, -climb) > headroom) m = min64(m, -climb - bs);
                for (i64 q = k0; q < k1; ++q) {
                    const i64 nb = hi[q];
                    if (min64(ts, ceil_[q]) - max64(bs, nb) > headroom) {
                        m = min64(m, nb - bs);
                        if (nb - bs <= climb && bs - nb <= climb) {
                            a0 = min64(a0, nb);
                            a1 = max64(a1, nb);
                        }
                    }
                }
            }
            if (m < -climb) led[s] = 1;
            else if (a1 - a0 > climb) stp[s] = 1;
        }
        for (Py_ssize_t s = 0; s < n; ++s) {
            /* 3. too little headroom, of what the ledge filter left */
            const int w2 = out[s] && !led[s] && !stp[s];
            lw[s] = w2 && (ceil_[s] - hi[s]) <= headroom;
            out[s] = w2 && !lw[s];
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    free(start);
    free(ceil_);
    PyBuffer_Release(&col);
    PyBuffer_Release(&smin);
    PyBuffer_Release(&smax);
    PyBuffer_Release(&walk);
    PyBuffer_Release(&w3);
    PyBuffer_Release(&lifted);
    PyBuffer_Release(&ledge);
    PyBuffer_Release(&steep);
    PyBuffer_Release(&low);
    return ret;
}

/* ------------------------------------------------------------------ chamfer on the grid */

/* the node a link of grid node s, at row i and column j, leads to (flat index over
 * (L, nz, nx)), -1 for none: no link, off the grid, or no node there */
static const int GDI[4] = {0, 1, 0, -1}, GDJ[4] = {1, 0, -1, 0};
static inline i64 grid_nb(const int8_t *link, const uint8_t *exists, i64 s, i64 i, i64 j, int d,
                          i64 per, i64 nz, i64 nx) {
    const int t = link[4 * s + d];
    if (t < 0) return -1;
    i += GDI[d];
    j += GDJ[d];
    if (i < 0 || i >= nz || j < 0 || j >= nx) return -1;
    const i64 a = (i64)t * per + i * nx + j;
    return exists[a] ? a : -1;
}

static inline int32_t grid_at(const int32_t *dist, i64 a) { return a < 0 ? 0 : dist[a]; }

/* relax() of grid node s at (i, j): straight steps 2, diagonal ones 3 either way round */
static inline int32_t grid_relax(const int8_t *K, const uint8_t *E, const int32_t *D, i64 s, i64 i, i64 j,
                                 i64 per, i64 nz, i64 nx, int32_t v) {
    i64 nb[4];
    for (int d = 0; d < 4; ++d) nb[d] = grid_nb(K, E, s, i, j, d, per, nz, nx);
    for (int d = 0; d < 4; ++d) {
        const int e = (d + 1) & 3;
        const i64 a = nb[d], b = nb[e];
        int32_t w = grid_at(D, a) + 2;
        if (w < v) v = w;
        w = (a < 0 ? 0 : grid_at(D, grid_nb(K, E, a, i + GDI[d], j + GDJ[d], e, per, nz, nx))) + 3;
        if (w < v) v = w;
        w = (b < 0 ? 0 : grid_at(D, grid_nb(K, E, b, i + GDI[e], j + GDJ[e], d, per, nz, nx))) + 3;
        if (w < v) v = w;
    }
    return v;
}

/* the nodes whose relaxation reads node s (lv, i, j): the 3 x 3 cells around it on
 * every level, marked dirty */
static inline void mark_around(uint8_t *dirty, const uint8_t *E, i64 L, i64 per, i64 nz, i64 nx, i64 i, i64 j) {
    for (i64 lv = 0; lv < L; ++lv)
        for (i64 a = i - 1; a <= i + 1; ++a) {
            if (a < 0 || a >= nz) continue;
            for (i64 b = j - 1; b <= j + 1; ++b) {
                if (b < 0 || b >= nx) continue;
                const i64 t = lv * per + a * nx + b;
                if (E[t]) dirty[t] = 1;
            }
        }
}

/* layers.surface_clearance on the ground's own arrays: the chamfer distance of
 * chamfer() over the graph its compact (n, 4) table describes, without that table
 * (16 bytes a node, and its int64 temporaries: +556 MB on a 1 km terrain).  The
 * fixed point is unique, so the values are chamfer()'s.  dist: int32 (L, nz, nx),
 * written (0 where no node).  Only dirty nodes are relaxed: those around a node below
 * the limit at the start (an edge) or lowered since (a node's relaxation reads the
 * 3 x 3 cells around it; one with all of them at the limit stays there): on a terrain
 * about 1 % of the nodes come below the limit, and the sweeps over every node took
 * 3.8 s on 2 km. */
static PyObject *chamfer_grid(PyObject *self, PyObject *args) {
    Py_buffer link, exists, dist;
    Py_ssize_t L, nz, nx;
    int limit;
    if (!PyArg_ParseTuple(args, "y*y*w*nnni", &link, &exists, &dist, &L, &nz, &nx, &limit)) return NULL;
    const i64 per = (i64)nz * nx, n = (i64)L * per;
    PyObject *ret = NULL;
    uint8_t *dirty = NULL;
    if (!need(&link, 4 * n, 1, "link") || !need(&exists, n, 1, "exists") || !need(&dist, n, 4, "dist")) goto done;
    dirty = calloc(n > 0 ? n : 1, 1);
    if (dirty == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const int8_t *K = link.buf;
        const uint8_t *E = exists.buf;
        int32_t *D = dist.buf;
        Py_BEGIN_ALLOW_THREADS
        for (i64 s = 0; s < n; ++s) {
            const i64 i = (s % per) / nx, j = s % nx;
            D[s] = 0;
            if (!E[s]) continue;
            D[s] = limit;
            for (int d = 0; d < 4; ++d)
                if (grid_nb(K, E, s, i, j, d, per, nz, nx) < 0) { D[s] = 1; break; }
        }
        for (i64 s = 0; s < n; ++s)
            if (E[s] && D[s] < limit) mark_around(dirty, E, L, per, nz, nx, (s % per) / nx, s % nx);
        int changed = 1;
        while (changed) {   /* forward and back sweeps, as chamfer(), over the dirty nodes */
            changed = 0;
            for (int back = 0; back < 2; ++back)
                for (i64 lv = 0; lv < L; ++lv)
                    for (i64 i = 0; i < nz; ++i)
                        for (i64 jj = 0; jj < nx; ++jj) {
                            const i64 l = back ? L - 1 - lv : lv, r = back ? nz - 1 - i : i;
                            const i64 j = back ? nx - 1 - jj : jj, s = l * per + r * nx + j;
                            if (!dirty[s]) continue;
                            dirty[s] = 0;
                            if (!E[s] || D[s] <= 1) continue;   /* 1: on the edge, no lower */
                            const int32_t v = grid_relax(K, E, D, s, r, j, per, nz, nx, D[s]);
                            if (v < D[s]) {
                                D[s] = v;
                                changed = 1;
                                mark_around(dirty, E, L, per, nz, nx, r, j);
                            }
                        }
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    free(dirty);
    PyBuffer_Release(&link);
    PyBuffer_Release(&exists);
    PyBuffer_Release(&dist);
    return ret;
}

static PyMethodDef methods[] = {
    {"link_spans", link_spans, METH_VARARGS, "links between open spans (see nav/kernels.py)"},
    {"chamfer", chamfer, METH_VARARGS, "chamfer distance relaxed to its fixed point, in place"},
    {"chamfer_near", tanktool_chamfer_near, METH_VARARGS, "chamfer() relaxing only near the last changes (walkable links)"},
    {"reach", reach, METH_VARARGS, "straight-step distance from the sources relaxed to its fixed point, in place"},
    {"filters", filters, METH_VARARGS, "Recast's three span filters, as span_filters.filter_masks"},
    {"components", components, METH_VARARGS, "component labels (smallest span index), in place"},
    {"walkable_faces", tanktool_walkable_faces, METH_VARARGS, "heightfield.walkable_faces' flags (_kernels_faces.c)"},
    {"flat_faces", tanktool_flat_faces, METH_VARARGS, "the upward flat faces' heights and areas (_kernels_faces.c)"},
    {"raster_merge", tanktool_raster_merge, METH_VARARGS, "every triangle's pieces merged into spans (_kernels_raster.c)"},
    {"grid_labels", tanktool_grid_labels, METH_VARARGS, "component labels of the grid's valid nodes (_kernels_grid.c)"},
    {"grid_links", tanktool_grid_links, METH_VARARGS, "the layered grid's links from the surface's (_kernels_grid.c)"},
    {"grid_runs", tanktool_grid_runs, METH_VARARGS, "the layered grid's row and column runs (_kernels_grid.c)"},
    {"chamfer_grid", chamfer_grid, METH_VARARGS, "chamfer() on the ground's (L, nz, nx, 4) int8 links, in place"},
    {"open_spans", tanktool_open_spans, METH_VARARGS, "the walkable spans' columns, floors, ceilings (_kernels_surface.c)"},
    {"snap_heights", tanktool_snap_heights, METH_VARARGS, "the open spans' floor heights (_kernels_surface.c)"},
    {"flat_floor_of", tanktool_flat_floor_of, METH_VARARGS, "level_walls' flat cells and their floors (_kernels_surface.c)"},
    {"scatter_layers", tanktool_scatter_layers, METH_VARARGS, "surface_layers' scatter (_kernels_surface.c)"},
    {"level_votes", tanktool_level_votes, METH_VARARGS, "levels by column rank, then the voting rounds (_kernels_surface.c)"},
    {"lift_portals", tanktool_lift_portals, METH_VARARGS, "level_lift.lift_to_portals in place (_kernels_surface.c)"},
    {"ground_tilt", tanktool_ground_tilt, METH_VARARGS, "Ground.tilt on the ground's arrays (_kernels_ground.c)"},
    {"ground_height", tanktool_ground_height, METH_VARARGS, "Ground.height on the ground's heights (_kernels_ground.c)"},
    {"ground_follow", tanktool_ground_follow, METH_VARARGS, "Ground.follow on the ground's links (_kernels_ground.c)"},
    {"grid_walk", tanktool_grid_walk, METH_VARARGS, "layers._walked: the agents' coarse links (_kernels_ground.c)"},
    {"grade_cut", tanktool_grade_cut, METH_VARARGS, "layers._cut_grade in place (_kernels_ground.c)"},
    {"solid_visible", tanktool_solid_visible, METH_VARARGS, "SolidField.visible's lines of sight (_kernels_ground.c)"},
    {"astar_layered", tanktool_astar_layered, METH_VARARGS, "nav.path.astar_layered's search (_kernels_path.c)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_kernels", "tanktool's compiled kernels", -1, methods};

/* ABI: raised whenever a kernel's name or arguments change; geometry/kernels.py uses a
   build only when it matches (an editable install keeps an old build in the tree). */
#define TANKTOOL_KERNELS_ABI 18
PyMODINIT_FUNC PyInit__kernels(void) {
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && PyModule_AddIntConstant(m, "ABI", TANKTOOL_KERNELS_ABI) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
