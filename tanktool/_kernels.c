/* tanktool._kernels: the walkable-surface loops numpy cannot make fast, in C.
 *
 * Optional: setup.py builds it when a C compiler is there; tanktool/nav/kernels.py
 * falls back to numpy otherwise, with identical results (tests/test_kernels.py
 * compares the two).  No numpy headers: arrays come in through the buffer protocol
 * (C-contiguous, the dtypes kernels.py makes sure of), so building needs only
 * Python's own headers.
 *
 *   link_spans(col, floor, ceil, start, nz, nx, headroom, climb, out)
 *       col, floor, ceil, start: int64; out: int64 (n, 4), filled in place
 *   chamfer(link, dist, limit)
 *       link: int64 (n, 4); dist: int32 (n,), the starting values, relaxed in place
 *   raster(tri, abc, nz, nx, ch, max_steps, row_lo, row_hi, steep) -> (col, tri, smin, smax) as int64 bytes
 *       (the cells of rows row_lo .. row_hi - 1 only); steep: the triangles' exact sections
 *       (heightfield._cells_exact) instead of their planes (_cells_plane; abc unused)
 *       tri: float64 (n, 9) x0 x1 x2 z0 z1 z2 y0 y1 y2 in grid units (y in metres);
 *       abc: float64 (n, 3) the plane y = A + B x + C z of each triangle
 *   filters(col, smin, smax, walk, nz, nx, headroom, climb, w3, lifted, ledge, steep, low)
 *       int64 spans, bool walk; the five bool outputs of span_filters.filter_masks
 *   components(link, label)
 *       link: int64 (n, 4); label: int64 (n,) written: the smallest span of each component
 *   merge_spans(key, thr, col, smin, smax, walk, flat, top_walk) -> count
 *       key: sorted int64 packed pieces; outputs int64 / bool arrays as long as key
 *
 * Built with -ffp-contract=off: no fused multiply-adds, so the floating-point results
 * are those of numpy's one operation at a time.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef int64_t i64;

/* the four directions +x, +z, -x, -z as (di, dj), as heightfield.neighbour_columns */
static const int DI[4] = {0, 1, 0, -1};
static const int DJ[4] = {1, 0, -1, 0};

static int need(Py_buffer *b, Py_ssize_t items, Py_ssize_t itemsize, const char *name) {
    if (b->len != items * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd bytes, got %zd", name, items * itemsize, b->len);
        return 0;
    }
    return 1;
}

static inline i64 min64(i64 a, i64 b) { return a < b ? a : b; }
static inline i64 max64(i64 a, i64 b) { return a > b ? a : b; }

static PyObject *link_spans(PyObject *self, PyObject *args) {
    Py_buffer col, floor_, ceil_, start, out;
    i64 nz, nx, headroom, climb;
    if (!PyArg_ParseTuple(args, "y*y*y*y*LLLLw*", &col, &floor_, &ceil_, &start, &nz, &nx, &headroom, &climb,
                          &out))
        return NULL;
    Py_ssize_t n = col.len / 8;
    PyObject *ret = NULL;
    if (!need(&floor_, n, 8, "floor") || !need(&ceil_, n, 8, "ceil") || !need(&start, nz * nx + 1, 8, "start") ||
        !need(&out, 4 * n, 8, "out"))
        goto done;
    {
        const i64 *c = col.buf, *f = floor_.buf, *ce = ceil_.buf, *st = start.buf;
        i64 *o = out.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0; s < n; ++s) {
            const i64 i = c[s] / nx, j = c[s] % nx;
            for (int d = 0; d < 4; ++d) {
                const i64 ii = i + DI[d], jj = j + DJ[d];
                i64 found = -1;
                if (ii >= 0 && ii < nz && jj >= 0 && jj < nx) {
                    const i64 nc = ii * nx + jj;
                    for (i64 k = st[nc]; k < st[nc + 1]; ++k) {
                        const i64 gap = min64(ce[s], ce[k]) - max64(f[s], f[k]);
                        const i64 dy = f[k] - f[s];
                        if (gap >= headroom && (dy <= climb && -dy <= climb)) {
                            found = k;
                            break;
                        }
                    }
                }
                o[4 * s + d] = found;
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

/* the value at span a, 0 off the edge (a < 0: the sentinel of chamfer_clearance) */
static inline int32_t at(const int32_t *dist, i64 a) { return a < 0 ? 0 : dist[a]; }

/* one relaxation of span s: straight steps cost 2, diagonal ones (a straight link,
 * then the next direction's link from there, either way round) 3 */
static inline int32_t relax(const i64 *L, const int32_t *dist, Py_ssize_t s, int32_t v) {
    const i64 *l = L + 4 * s;
    for (int d = 0; d < 4; ++d) {
        const int e = (d + 1) & 3;
        const i64 a = l[d], b = l[e];
        int32_t w = at(dist, a) + 2;
        if (w < v) v = w;
        w = (a < 0 ? 0 : at(dist, L[4 * a + e])) + 3;
        if (w < v) v = w;
        w = (b < 0 ? 0 : at(dist, L[4 * b + d])) + 3;
        if (w < v) v = w;
    }
    return v;
}

static PyObject *chamfer(PyObject *self, PyObject *args) {
    Py_buffer link, dist;
    int limit;
    if (!PyArg_ParseTuple(args, "y*w*i", &link, &dist, &limit)) return NULL;
    Py_ssize_t n = dist.len / 4;
    PyObject *ret = NULL;
    if (!need(&link, 4 * n, 8, "link")) goto done;
    {
        const i64 *L = link.buf;
        int32_t *D = dist.buf;
        Py_BEGIN_ALLOW_THREADS
        /* sweeps forward and back (spans come in scan order, so each sweep carries a
         * distance across the level) until nothing changes: the same fixed point as
         * the numpy relaxation, every span at its shortest chamfer path, capped at limit */
        int changed = 1;
        while (changed) {
            changed = 0;
            for (Py_ssize_t s = 0; s < n; ++s) {
                const int32_t v = relax(L, D, s, D[s]);
                if (v < D[s]) { D[s] = v; changed = 1; }
            }
            for (Py_ssize_t s = n - 1; s >= 0; --s) {
                const int32_t v = relax(L, D, s, D[s]);
                if (v < D[s]) { D[s] = v; changed = 1; }
            }
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&link);
    PyBuffer_Release(&dist);
    return ret;
}


/* ------------------------------------------------------------------ rasterising */

/* growable int64 columns of the rasteriser's output */
typedef struct {
    i64 *col, *tri, *smin, *smax;
    Py_ssize_t n, cap;
} Cells;

static int cells_push(Cells *c, i64 col, i64 tri, i64 smin, i64 smax) {
    if (c->n == c->cap) {
        Py_ssize_t cap = c->cap ? 2 * c->cap : 1024;
        i64 *a = realloc(c->col, cap * 8), *b = a ? realloc(c->tri, cap * 8) : NULL;
        if (a) c->col = a;
        if (b) c->tri = b;
        i64 *d = b ? realloc(c->smin, cap * 8) : NULL;
        if (d) c->smin = d;
        i64 *e = d ? realloc(c->smax, cap * 8) : NULL;
        if (e) c->smax = e;
        if (!e) return 0;
        c->cap = cap;
    }
    c->col[c->n] = col;
    c->tri[c->n] = tri;
    c->smin[c->n] = smin;
    c->smax[c->n] = smax;
    c->n++;
    return 1;
}

/* numpy's fmin / fmax (a NaN is ignored), np.minimum / np.maximum on numbers */
static inline double fmin_(double a, double b) { return isnan(b) ? a : (isnan(a) ? b : (b < a ? b : a)); }
static inline double fmax_(double a, double b) { return isnan(b) ? a : (isnan(a) ? b : (b > a ? b : a)); }
static inline double mind(double a, double b) { return b < a ? b : a; }
static inline double maxd(double a, double b) { return b > a ? b : a; }

/* _quantise: bottom and top in cell-height steps, at least one step */
static inline void quantise(double ymin, double ymax, double ch, i64 maxh, i64 *lo, i64 *hi) {
    double a = floor(ymin / ch);
    a = mind(maxd(a, 0.0), (double)maxh);
    const i64 smin = (i64)a;
    double b = ceil(ymax / ch);
    b = mind(maxd(b, (double)(smin + 1)), (double)maxh);
    *lo = smin;
    *hi = (i64)b;
}


/* heightfield._sections: the section of a triangle by the line u = a in the (u, v)
 * plane (u, v, y: its vertices in their own order) */
typedef struct {
    double vlo, ylo, vhi, yhi, ymn, ymx;
} Section;

static inline void take(Section *s, double vv, double yy) {
    if (vv < s->vlo) s->ylo = yy;
    if (vv > s->vhi) s->yhi = yy;
    s->vlo = mind(s->vlo, vv);
    s->vhi = maxd(s->vhi, vv);
    s->ymn = mind(s->ymn, yy);
    s->ymx = maxd(s->ymx, yy);
}

static int section(const double *U, const double *V, const double *Y, double a, Section *s) {
    s->vlo = INFINITY;
    s->vhi = -INFINITY;
    s->ylo = s->yhi = 0.0;
    s->ymn = INFINITY;
    s->ymx = -INFINITY;
    for (int k = 0; k < 3; ++k)
        if (U[k] == a) take(s, V[k], Y[k]);
    static const int E[3][2] = {{0, 1}, {1, 2}, {2, 0}};
    for (int e = 0; e < 3; ++e) {
        const int i = E[e][0], j = E[e][1];
        const double du = U[j] - U[i];
        if ((U[i] - a) * (U[j] - a) < 0) {
            const double t = (a - U[i]) / du;
            take(s, V[i] + t * (V[j] - V[i]), Y[i] + t * (Y[j] - Y[i]));
        }
    }
    return isfinite(s->vlo);
}

/* growable scratch of doubles */
typedef struct {
    double *v;
    Py_ssize_t cap;
} Scratch;

static double *scratch(Scratch *s, Py_ssize_t n) {
    if (n > s->cap) {
        double *v = realloc(s->v, n * sizeof(double));
        if (!v) return NULL;
        s->v = v;
        s->cap = n;
    }
    return s->v;
}

/* heightfield._cells_exact for one (triangle, row) pair: the y range over Q's vertices
 * in each cell and the triangle's sections by the cell's two x lines, clipped to the
 * slab [z0, z1] */
static int cells_exact(Cells *out, Scratch *buf, i64 t, const double *X, const double *Z, const double *Y, i64 row,
                       i64 nx, i64 j0, i64 ncell, double z0, double z1, const double *qx, const double *qy, double ch,
                       i64 maxh) {
    double *lo_l = scratch(buf, 4 * (ncell + 1));
    if (!lo_l) return 0;
    double *hi_l = lo_l + (ncell + 1), *ymin = hi_l + (ncell + 1), *ymax = ymin + (ncell + 1);
    const double xlo = mind(mind(X[0], X[1]), X[2]), xhi = maxd(maxd(X[0], X[1]), X[2]);
    const double a0 = ceil(xlo), a1 = floor(xhi);
    for (i64 k = 0; k <= ncell; ++k) {
        const double a = (double)(j0 + k);
        Section s;
        int ok = a >= a0 && a <= a1 && section(X, Z, Y, a, &s);
        lo_l[k] = INFINITY;
        hi_l[k] = -INFINITY;
        if (!ok) continue;
        const int vertical = s.vhi == s.vlo;
        if (vertical) {
            if (s.vlo >= z0 && s.vlo <= z1) {
                lo_l[k] = s.ymn;
                hi_l[k] = s.ymx;
            }
            continue;
        }
        const double za = maxd(s.vlo, z0), zb = mind(s.vhi, z1);
        if (!(za <= zb)) continue;
        const double slope = (s.yhi - s.ylo) / (s.vhi - s.vlo);
        const double ya = s.ylo + (za - s.vlo) * slope, yb = s.ylo + (zb - s.vlo) * slope;
        lo_l[k] = mind(ya, yb);
        hi_l[k] = maxd(ya, yb);
    }
    for (i64 k = 0; k < ncell; ++k) {
        ymin[k] = mind(lo_l[k], lo_l[k + 1]);
        ymax[k] = maxd(hi_l[k], hi_l[k + 1]);
    }
    for (int q = 0; q < 5; ++q) {  /* Q's vertices, each in the cell of its column */
        const double jj = floor(qx[q]) - (double)j0;
        if (jj >= 0 && jj < (double)ncell) {
            const i64 k = (i64)jj;
            ymin[k] = mind(ymin[k], qy[q]);
            ymax[k] = maxd(ymax[k], qy[q]);
        }
    }
    for (i64 k = 0; k < ncell; ++k) {
        if (!isfinite(ymin[k])) continue;
        i64 s0, s1;
        quantise(ymin[k], ymax[k], ch, maxh, &s0, &s1);
        if (!cells_push(out, row * nx + j0 + k, t, s0, s1)) return 0;
    }
    return 1;
}

/* heightfield._rows and _cells_plane for one gentle triangle (y = A + B x + C z in grid
 * units), the same arithmetic in the same order so that the spans are identical */
static int raster_one(Cells *out, Scratch *buf, int steep, i64 t, const double *X, const double *Z, const double *Y,
                      double A, double B, double C, i64 row_lo, i64 row_hi, i64 nx, double ch, i64 maxh) {
    double z[3] = {Z[0], Z[1], Z[2]}, x[3] = {X[0], X[1], X[2]}, y[3] = {Y[0], Y[1], Y[2]};
    static const int net[3][2] = {{0, 1}, {1, 2}, {0, 1}};  /* _sort3's network */
    for (int k = 0; k < 3; ++k) {
        const int a = net[k][0], b = net[k][1];
        if (z[a] > z[b]) {
            double tmp;
            tmp = z[a]; z[a] = z[b]; z[b] = tmp;
            tmp = x[a]; x[a] = x[b]; x[b] = tmp;
            tmp = y[a]; y[a] = y[b]; y[b] = tmp;
        }
    }
    const double za = z[0], zb = z[1], zc = z[2], xa = x[0], xb = x[1], xc = x[2], ya = y[0], yb = y[1], yc = y[2];
    const double inv_ac = zc > za ? 1.0 / (zc - za) : 0.0;
    const double inv_ab = zb > za ? 1.0 / (zb - za) : 0.0;
    const double inv_bc = zc > zb ? 1.0 / (zc - zb) : 0.0;
    const double r0t = floor(za);
    const double r1t = zc > za ? ceil(zc) - 1 : r0t;
    const double r0 = maxd(r0t, (double)row_lo), r1 = mind(r1t, (double)(row_hi - 1));
    const i64 nrow = (i64)maxd(r1 - r0 + 1, 0.0);
    if (nrow <= 0) return 1;
    const int flat_z = za == zc;
    double lx0 = 0, ly0 = 0, sx0 = 0, sy0 = 0;
    for (i64 k = 0; k <= nrow; ++k) {
        /* the sections at line L = r0 + k: on the long edge a-c and on the short side */
        const double L = r0 + (double)k;
        double tt = (L - za) * inv_ac;
        const double lx = xa + tt * (xc - xa), ly = ya + tt * (yc - ya);
        const int lower = L <= zb;
        tt = (L - (lower ? za : zb)) * (lower ? inv_ab : inv_bc);
        const double sx = (lower ? xa : xb) + tt * (lower ? (xb - xa) : (xc - xb));
        const double sy = (lower ? ya : yb) + tt * (lower ? (yb - ya) : (yc - yb));
        if (k > 0) {  /* the pair of row r0 + k - 1: lines k - 1 and k */
            const i64 row = (i64)r0 + k - 1;
            const double c = (double)row;
            const int first = c == r0t, last = c == r1t;
            double qx[5], qy[5];
            qx[0] = first ? xa : lx0;
            qy[0] = first ? ya : ly0;
            qx[1] = first ? xa : sx0;
            qy[1] = first ? ya : sy0;
            qx[2] = last ? xc : lx;
            qy[2] = last ? yc : ly;
            qx[3] = last ? xc : sx;
            qy[3] = last ? yc : sy;
            const int mid = (zb > c && zb < c + 1.0) || flat_z;
            qx[4] = mid ? xb : NAN;
            qy[4] = mid ? yb : NAN;
            const double z0 = maxd(c, za), z1 = mind(c + 1.0, zc);
            double lo = qx[0], hi = qx[0], ylo = qy[0], yhi = qy[0];
            for (int q = 1; q < 5; ++q) {
                lo = fmin_(lo, qx[q]);
                hi = fmax_(hi, qx[q]);
                ylo = fmin_(ylo, qy[q]);
                yhi = fmax_(yhi, qy[q]);
            }
            const double jf = floor(lo);
            const double jl = hi > lo ? ceil(hi) - 1 : jf;
            const double j0f = maxd(jf, 0.0), j1f = mind(jl, (double)(nx - 1));
            if ((z1 > z0 || flat_z) && j1f >= j0f && steep) {
                if (!cells_exact(out, buf, t, X, Z, Y, row, nx, (i64)j0f, (i64)(j1f - j0f + 1), z0, z1, qx, qy, ch,
                                 maxh))
                    return 0;
            } else if ((z1 > z0 || flat_z) && j1f >= j0f) {
                const i64 j0 = (i64)j0f, ncell = (i64)(j1f - j0f + 1);
                const double band = floor(ylo / ch);
                if (band == floor(yhi / ch)) {  /* the whole row within one cell height */
                    const i64 su = (i64)mind(maxd(band, 0.0), (double)(maxh - 1));
                    for (i64 q = 0; q < ncell; ++q)
                        if (!cells_push(out, row * nx + j0 + q, t, su, su + 1)) return 0;
                } else {
                    const double zlo = A + mind(C * z0, C * z1), zhi = A + maxd(C * z0, C * z1);
                    for (i64 q = 0; q < ncell; ++q) {
                        const double j = (double)(j0 + q);
                        const double x0 = maxd(j, lo), x1 = mind(j + 1.0, hi);
                        const double ba = B * x0, bb = B * x1;
                        const double ymin = maxd(zlo + mind(ba, bb), ylo);
                        const double ymax = mind(zhi + maxd(ba, bb), yhi);
                        i64 s0, s1;
                        quantise(ymin, maxd(ymax, ymin), ch, maxh, &s0, &s1);
                        if (!cells_push(out, row * nx + j0 + q, t, s0, s1)) return 0;
                    }
                }
            }
        }
        lx0 = lx;
        ly0 = ly;
        sx0 = sx;
        sy0 = sy;
    }
    return 1;
}

static PyObject *as_bytes(const i64 *a, Py_ssize_t n) {
    return PyBytes_FromStringAndSize(n ? (const char *)a : "", n * 8);
}

static PyObject *raster(PyObject *self, PyObject *args) {
    Py_buffer tri, abc;
    i64 nz, nx, maxh, row_lo, row_hi;
    double ch;
    int steep;
    if (!PyArg_ParseTuple(args, "y*y*LLdLLLp", &tri, &abc, &nz, &nx, &ch, &maxh, &row_lo, &row_hi, &steep))
        return NULL;
    if (row_lo < 0) row_lo = 0;
    if (row_hi > nz) row_hi = nz;
    const Py_ssize_t n = tri.len / (9 * 8);
    PyObject *ret = NULL;
    Cells out = {0};
    Scratch buf = {0};
    int ok = 1;
    if (!need(&tri, 9 * n, 8, "tri") || !need(&abc, 3 * n, 8, "abc")) goto done;
    {
        const double *T = tri.buf, *P = abc.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t t = 0; t < n && ok; ++t) {
            const double *v = T + 9 * t; /* x0 x1 x2 z0 z1 z2 y0 y1 y2 */
            ok = raster_one(&out, &buf, steep, t, v, v + 3, v + 6, P[3 * t], P[3 * t + 1], P[3 * t + 2], row_lo,
                            row_hi, nx, ch, maxh);
        }
        Py_END_ALLOW_THREADS
    }
    if (!ok) {
        PyErr_NoMemory();
        goto done;
    }
    ret = Py_BuildValue("(NNNN)", as_bytes(out.col, out.n), as_bytes(out.tri, out.n), as_bytes(out.smin, out.n),
                        as_bytes(out.smax, out.n));
done:
    free(buf.v);
    free(out.col);
    free(out.tri);
    free(out.smin);
    free(out.smax);
    PyBuffer_Release(&tri);
    PyBuffer_Release(&abc);
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
    if (!need(&link, 4 * n, 8, "link")) goto done;
    {
        const i64 *L = link.buf;
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

/* ------------------------------------------------------------------ merging */

/* heightfield._merge over the sorted packed keys (column << 34 | bottom << 18 | top << 2
 * | walkable << 1 | flat): the overlapping or touching pieces of a column become one
 * span; its flags are those of the pieces whose tops lie within thr of its top (and
 * top_walk: of the pieces reaching its very top).  Writes the spans into the six
 * output arrays (at most as long as the keys) and returns how many. */
static PyObject *merge_spans(PyObject *self, PyObject *args) {
    Py_buffer key, col, smin, smax, walk, flat, topw;
    i64 thr;
    if (!PyArg_ParseTuple(args, "y*Lw*w*w*w*w*w*", &key, &thr, &col, &smin, &smax, &walk, &flat, &topw))
        return NULL;
    const Py_ssize_t n = key.len / 8;
    Py_ssize_t m = 0;
    PyObject *ret = NULL;
    if (!need(&col, n, 8, "col") || !need(&smin, n, 8, "smin") || !need(&smax, n, 8, "smax") ||
        !need(&walk, n, 1, "walk") || !need(&flat, n, 1, "flat") || !need(&topw, n, 1, "top_walk"))
        goto done;
    {
        const i64 *K = key.buf;
        i64 *C = col.buf, *S0 = smin.buf, *S1 = smax.buf;
        char *W = walk.buf, *F = flat.buf, *T = topw.buf;
        Py_BEGIN_ALLOW_THREADS
        Py_ssize_t a = 0;
        while (a < n) {
            const i64 c = K[a] >> 34;
            i64 top = (K[a] >> 2) & 0xFFFF;
            Py_ssize_t b = a + 1;
            while (b < n && (K[b] >> 34) == c && ((K[b] >> 18) & 0xFFFF) <= top) {
                const i64 t = (K[b] >> 2) & 0xFFFF;
                if (t > top) top = t;
                ++b;
            }
            char w = 0, f = 0, tw = 0;
            for (Py_ssize_t k = a; k < b; ++k) {
                const i64 t = (K[k] >> 2) & 0xFFFF;
                const int kw = (K[k] & 2) != 0, kf = (K[k] & 1) != 0;
                if (t >= top - thr) {
                    w |= kw;
                    f |= kf;
                }
                if (t == top) tw |= kw;
            }
            C[m] = c;
            S0[m] = (K[a] >> 18) & 0xFFFF;
            S1[m] = top;
            W[m] = w;
            F[m] = f;
            T[m] = tw;
            ++m;
            a = b;
        }
        Py_END_ALLOW_THREADS
    }
    ret = PyLong_FromSsize_t(m);
done:
    PyBuffer_Release(&key);
    PyBuffer_Release(&col);
    PyBuffer_Release(&smin);
    PyBuffer_Release(&smax);
    PyBuffer_Release(&walk);
    PyBuffer_Release(&flat);
    PyBuffer_Release(&topw);
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

static PyMethodDef methods[] = {
    {"link_spans", link_spans, METH_VARARGS, "links between open spans (see nav/kernels.py)"},
    {"chamfer", chamfer, METH_VARARGS, "chamfer distance relaxed to its fixed point, in place"},
    {"raster", raster, METH_VARARGS, "spans of triangles, as heightfield._cells_plane / _cells_exact"},
    {"filters", filters, METH_VARARGS, "Recast's three span filters, as span_filters.filter_masks"},
    {"components", components, METH_VARARGS, "component labels (smallest span index), in place"},
    {"merge_spans", merge_spans, METH_VARARGS, "the merged spans of sorted packed keys"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_kernels", "tanktool's compiled kernels", -1, methods};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module); }
