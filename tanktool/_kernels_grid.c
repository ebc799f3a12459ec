/* tanktool._kernels: loops over the navigation grid's nodes (see _kernels.c).
 *
 *   grid_labels(valid, link, L, nz, nx, out) -> k
 *       valid: bool (L, nz, nx); link: int8 (L, nz, nx, 4) the level each node's step in
 *       direction d (+x, +z, -x, -z) reaches, -1 for none; out: int32 (L, nz, nx)
 *       written: the component of each valid node over the steps between valid nodes
 *       (either way), numbered 1..k in the order of each component's first node, as
 *       scipy's connected_components numbers them; 0 where there is no valid node
 *       (arena_levels.grid_components, navgrid.layered_reachable)
 *
 * Why in C: numpy's way builds the step graph as (source, target) index pairs and
 * hands it to scipy, some 70 bytes a node at its peak (a gigabyte on a 1 km terrain at
 * 0.5 m); union-find over the grid itself needs the 4 bytes a node of the labels.
 */
#include "_kernels.h"

static const int GDI[4] = {0, 1, 0, -1};
static const int GDJ[4] = {1, 0, -1, 0};

static inline int32_t root32(int32_t *parent, int32_t a) {
    while (parent[a] != a) {
        parent[a] = parent[parent[a]];  /* path halving */
        a = parent[a];
    }
    return a;
}

PyObject *tanktool_grid_labels(PyObject *self, PyObject *args) {
    Py_buffer valid, link, out;
    long long L, nz, nx;
    if (!PyArg_ParseTuple(args, "y*y*LLLw*", &valid, &link, &L, &nz, &nx, &out)) return NULL;
    const Py_ssize_t n = (Py_ssize_t)(L * nz * nx);
    PyObject *ret = NULL;
    long long k = 0;
    if (!need(&valid, n, 1, "valid") || !need(&link, 4 * n, 1, "link") || !need(&out, n, 4, "out")) goto done;
    if (n >= INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "grid_labels: more than 2**31 nodes");
        goto done;
    }
    {
        const uint8_t *V = valid.buf;
        const int8_t *K = link.buf;
        int32_t *P = out.buf;  /* the union-find's parents first, then the labels */
        const i64 per = nz * nx;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0; s < n; ++s) P[s] = (int32_t)s;
        /* the node's (l, i, j) by the loops, not by three divisions a node; its root
           found once and kept while its steps join it to others (any order of the
           unions gives the same sets, so the same labels): hix 44 -> 30 ms a call */
        for (i64 l = 0, s = 0; l < L; ++l)
            for (i64 i = 0; i < nz; ++i)
                for (i64 j = 0; j < nx; ++j, ++s) {
                    if (!V[s]) continue;
                    int32_t a = -1;
                    for (int d = 0; d < 4; ++d) {
                        const int tl = K[4 * s + d];
                        const i64 ii = i + GDI[d], jj = j + GDJ[d];
                        if (tl < 0 || tl >= L || ii < 0 || ii >= nz || jj < 0 || jj >= nx) continue;
                        const i64 t = tl * per + ii * nx + jj;
                        if (!V[t]) continue;
                        if (a < 0) a = root32(P, (int32_t)s);
                        const int32_t b = root32(P, (int32_t)t);
                        if (a == b) continue;
                        if (a < b) P[b] = a; else { P[a] = b; a = b; }  /* a root is its set's first node */
                    }
                }
        /* in node order (a parent always comes before its child: a root is its set's
           first node, and path halving only moves a parent earlier): a root takes the
           next label, any other node its parent's, which is labelled already (a node's
           own entry is still its parent when its turn comes: one pass) */
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (!V[s]) P[s] = 0;
            else if (P[s] == s) P[s] = (int32_t)(++k);
            else P[s] = P[P[s]];
        }
        Py_END_ALLOW_THREADS
    }
    ret = PyLong_FromLongLong(k);
done:
    PyBuffer_Release(&valid);
    PyBuffer_Release(&link);
    PyBuffer_Release(&out);
    return ret;
}

/* walkable.grid_from_surface's links: for every node with a span (span_of >= 0), the
 * level of the span its span links to in each direction when that span is a node of
 * the grid (its level >= 0 and the node exists), else -1; one pass, no temporaries.
 *   grid_links(span_of int32 (N), link int32 (n, 4), level int64 (n), col int64 (n),
 *              exists bool (N), per, out int8 (N, 4)) */
PyObject *tanktool_grid_links(PyObject *self, PyObject *args) {
    Py_buffer span_of, link, level, col, exists, out;
    long long per;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*Lw*", &span_of, &link, &level, &col, &exists, &per, &out)) return NULL;
    const Py_ssize_t N = span_of.len / 4, n = level.len / 8;
    PyObject *ret = NULL;
    if (!need(&link, 4 * n, 4, "link") || !need(&col, n, 8, "col") || !need(&exists, N, 1, "exists") ||
        !need(&out, 4 * N, 1, "out"))
        goto done;
    {
        const int32_t *S = span_of.buf, *K = link.buf;
        const i64 *LV = level.buf, *C = col.buf;
        const uint8_t *E = exists.buf;
        int8_t *O = out.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t a = 0; a < N; ++a) {
            const int32_t s = S[a];
            for (int d = 0; d < 4; ++d) {
                int8_t v = -1;
                if (s >= 0 && s < n) {
                    const int32_t t = K[4 * (i64)s + d];
                    if (t >= 0 && t < n && LV[t] >= 0) {
                        const i64 b = LV[t] * per + C[t];
                        if (b >= 0 && b < N && E[b]) v = (int8_t)LV[t];
                    }
                }
                O[4 * a + d] = v;
            }
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&span_of);
    PyBuffer_Release(&link);
    PyBuffer_Release(&level);
    PyBuffer_Release(&col);
    PyBuffer_Release(&exists);
    PyBuffer_Release(&out);
    return ret;
}

/* one line of nodes (a row along +x, d = 0, or a column along +z, d = 1, of one level
 * l): runs of valid nodes each linked to the next on the same level; a node's 1-based
 * place in its run and the run's length (0 and 0 off the valid nodes) */
static void runs_line(const uint8_t *V, const int8_t *K, i64 first, i64 step, i64 count, int d, int l,
                      int32_t *index, int32_t *total) {
    i64 j = 0;
    while (j < count) {
        const i64 a = first + j * step;
        if (!V[a]) {
            index[a] = 0;
            total[a] = 0;
            ++j;
            continue;
        }
        const i64 start = j;
        while (j + 1 < count && K[4 * (first + j * step) + d] == l && V[first + (j + 1) * step]) ++j;
        const int32_t len = (int32_t)(j - start + 1);
        for (i64 k = start; k <= j; ++k) {
            index[first + k * step] = (int32_t)(k - start + 1);
            total[first + k * step] = len;
        }
        ++j;
    }
}

/* the column runs of level l (along +z, d = 1), as runs_line gives them column by
 * column, but row by row: a column's nodes are nx apart, and walking them one column at
 * a time touched a new cache line at every node (hix's 1604 x 1604 grid: 52 -> 12 ms of CPU
 * a call).  Down the rows, a node's place is one more than the node's below when that
 * one continues into it; back up the rows, a run's length comes down from its last node. */
static void cols_rowwise(const uint8_t *V, const int8_t *K, i64 base, i64 nz, i64 nx, int l, int32_t *index,
                         int32_t *total) {
    for (i64 i = 0; i < nz; ++i) {
        const i64 row = base + i * nx;
        for (i64 j = 0; j < nx; ++j) {
            const i64 a = row + j, b = a - nx;
            index[a] = !V[a] ? 0 : (i > 0 && V[b] && K[4 * b + 1] == l) ? index[b] + 1 : 1;
        }
    }
    for (i64 i = nz - 1; i >= 0; --i) {
        const i64 row = base + i * nx;
        for (i64 j = 0; j < nx; ++j) {
            const i64 a = row + j, c = a + nx;
            total[a] = !V[a] ? 0 : (i + 1 < nz && V[c] && K[4 * a + 1] == l) ? total[c] : index[a];
        }
    }
}

/* navgrid.layered_runs: grid_runs(valid bool (L, nz, nx), link int8 (L, nz, nx, 4), L, nz,
 * nx, row_index, row_total, col_index, col_total int32 (L, nz, nx)) */
PyObject *tanktool_grid_runs(PyObject *self, PyObject *args) {
    Py_buffer valid, link, ri, rt, ci, ct;
    long long L, nz, nx;
    if (!PyArg_ParseTuple(args, "y*y*LLLw*w*w*w*", &valid, &link, &L, &nz, &nx, &ri, &rt, &ci, &ct)) return NULL;
    const Py_ssize_t n = (Py_ssize_t)(L * nz * nx);
    PyObject *ret = NULL;
    if (!need(&valid, n, 1, "valid") || !need(&link, 4 * n, 1, "link") || !need(&ri, n, 4, "row_index") ||
        !need(&rt, n, 4, "row_total") || !need(&ci, n, 4, "col_index") || !need(&ct, n, 4, "col_total"))
        goto done;
    if (L > 127) {
        PyErr_SetString(PyExc_ValueError, "grid_runs: more than 127 levels (int8 links)");
        goto done;
    }
    {
        const uint8_t *V = valid.buf;
        const int8_t *K = link.buf;
        Py_BEGIN_ALLOW_THREADS
        for (i64 l = 0; l < L; ++l) {
            const i64 base = l * nz * nx;
            for (i64 i = 0; i < nz; ++i)
                runs_line(V, K, base + i * nx, 1, nx, 0, (int)l, ri.buf, rt.buf);
            cols_rowwise(V, K, base, nz, nx, (int)l, ci.buf, ct.buf);
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&valid);
    PyBuffer_Release(&link);
    PyBuffer_Release(&ri);
    PyBuffer_Release(&rt);
    PyBuffer_Release(&ci);
    PyBuffer_Release(&ct);
    return ret;
}
