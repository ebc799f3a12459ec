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
 *   ledge_scan(s_col, bot, top, start, smin, smax, ceil, nz, nx, headroom, climb, minh, asmin, asmax)
 *       all int64; minh, asmin, asmax updated in place (Recast's rcFilterLedgeSpans)
 *   chamfer(link, dist, limit)
 *       link: int64 (n, 4); dist: int32 (n,), the starting values, relaxed in place
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>

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

static PyObject *ledge_scan(PyObject *self, PyObject *args) {
    Py_buffer scol, bot, top, start, smin, smax, ceil_, minh, asmin, asmax;
    i64 nz, nx, headroom, climb;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*y*LLLLw*w*w*", &scol, &bot, &top, &start, &smin, &smax, &ceil_, &nz,
                          &nx, &headroom, &climb, &minh, &asmin, &asmax))
        return NULL;
    Py_ssize_t n = scol.len / 8, spans = smin.len / 8;
    PyObject *ret = NULL;
    if (!need(&bot, n, 8, "bot") || !need(&top, n, 8, "top") || !need(&start, nz * nx + 1, 8, "start") ||
        !need(&smax, spans, 8, "smax") || !need(&ceil_, spans, 8, "ceil") || !need(&minh, n, 8, "minh") ||
        !need(&asmin, n, 8, "asmin") || !need(&asmax, n, 8, "asmax"))
        goto done;
    {
        const i64 *c = scol.buf, *b = bot.buf, *t = top.buf, *st = start.buf, *lo = smin.buf, *hi = smax.buf,
                  *ce = ceil_.buf;
        i64 *mh = minh.buf, *amn = asmin.buf, *amx = asmax.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0; s < n; ++s) {
            const i64 i = c[s] / nx, j = c[s] % nx, bs = b[s], ts = t[s];
            i64 m = mh[s], a0 = amn[s], a1 = amx[s];
            for (int d = 0; d < 4; ++d) {
                const i64 ii = i + DI[d], jj = j + DJ[d];
                if (!(ii >= 0 && ii < nz && jj >= 0 && jj < nx)) {  /* off the grid: a drop */
                    m = min64(m, -climb - bs);
                    continue;
                }
                const i64 nc = ii * nx + jj, k0 = st[nc], k1 = st[nc + 1];
                /* the floor below the neighbour's first span (open sky over an empty column) */
                const i64 ntop0 = k1 > k0 ? lo[k0] : OPEN;
                if (min64(ts, ntop0) - max64(bs, -climb) > headroom) m = min64(m, -climb - bs);
                for (i64 k = k0; k < k1; ++k) {
                    const i64 nb = hi[k];
                    if (min64(ts, ce[k]) - max64(bs, nb) > headroom) {
                        m = min64(m, nb - bs);
                        if (nb - bs <= climb && bs - nb <= climb) {
                            a0 = min64(a0, nb);
                            a1 = max64(a1, nb);
                        }
                    }
                }
            }
            mh[s] = m;
            amn[s] = a0;
            amx[s] = a1;
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&scol);
    PyBuffer_Release(&bot);
    PyBuffer_Release(&top);
    PyBuffer_Release(&start);
    PyBuffer_Release(&smin);
    PyBuffer_Release(&smax);
    PyBuffer_Release(&ceil_);
    PyBuffer_Release(&minh);
    PyBuffer_Release(&asmin);
    PyBuffer_Release(&asmax);
    return ret;
}

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

static PyMethodDef methods[] = {
    {"link_spans", link_spans, METH_VARARGS, "links between open spans (see nav/kernels.py)"},
    {"ledge_scan", ledge_scan, METH_VARARGS, "the ledge filter's scan of neighbour columns"},
    {"chamfer", chamfer, METH_VARARGS, "chamfer distance relaxed to its fixed point, in place"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_kernels", "tanktool's compiled kernels", -1, methods};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module); }
