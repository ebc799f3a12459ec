/* tanktool._kernels: loops over the navigation grid's nodes (see _kernels.c).
 *
 *   grid_reach(valid, link, L, nz, nx, seeds, out)
 *       valid: bool (L, nz, nx); link: int8 (L, nz, nx, 4) the level each node's link in
 *       direction d (+x, +z, -x, -z) reaches, -1 for none; seeds: int64 flat node
 *       indices; out: bool (L, nz, nx) written: the valid nodes connected through links
 *       between valid nodes to a valid seed (navgrid.layered_reachable)
 *
 * Why in C: numpy's way builds the link graph as (source, target) index pairs and
 * hands it to scipy, some 70 bytes a node at its peak (a gigabyte on a 1 km terrain at
 * 0.5 m); union-find over the grid itself needs 4 bytes a node.
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

PyObject *tanktool_grid_reach(PyObject *self, PyObject *args) {
    Py_buffer valid, link, seeds, out;
    long long L, nz, nx;
    if (!PyArg_ParseTuple(args, "y*y*LLLy*w*", &valid, &link, &L, &nz, &nx, &seeds, &out)) return NULL;
    const Py_ssize_t n = (Py_ssize_t)(L * nz * nx);
    const Py_ssize_t k = seeds.len / 8;
    PyObject *ret = NULL;
    int32_t *P = NULL;
    if (!need(&valid, n, 1, "valid") || !need(&link, 4 * n, 1, "link") || !need(&out, n, 1, "out")) goto done;
    if (n >= INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "grid_reach: more than 2**31 nodes");
        goto done;
    }
    P = malloc(sizeof(int32_t) * (n > 0 ? n : 1));
    if (P == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const uint8_t *V = valid.buf;
        const int8_t *K = link.buf;
        const i64 *S = seeds.buf;
        uint8_t *O = out.buf;
        const i64 per = nz * nx;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0; s < n; ++s) P[s] = (int32_t)s;
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (!V[s]) continue;
            const i64 ij = s % per, i = ij / nx, j = ij % nx;
            for (int d = 0; d < 4; ++d) {
                const int tl = K[4 * s + d];
                const i64 ii = i + GDI[d], jj = j + GDJ[d];
                if (tl < 0 || tl >= L || ii < 0 || ii >= nz || jj < 0 || jj >= nx) continue;
                const i64 t = tl * per + ii * nx + jj;
                if (!V[t]) continue;
                int32_t a = root32(P, (int32_t)s), b = root32(P, (int32_t)t);
                if (a == b) continue;
                if (a < b) P[b] = a; else P[a] = b;
            }
        }
        /* the seeds' roots (a handful): a node is kept when its root is one of them */
        for (Py_ssize_t s = 0; s < n; ++s) O[s] = 0;
        for (Py_ssize_t q = 0; q < k; ++q) {
            const i64 s = S[q];
            if (s < 0 || s >= n || !V[s]) continue;
            O[root32(P, (int32_t)s)] = 1;  /* marks roots; non-roots are cleared below */
        }
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (!V[s]) continue;
            const int32_t r = root32(P, (int32_t)s);
            if (r != s && O[r]) O[s] = 1;
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    free(P);
    PyBuffer_Release(&valid);
    PyBuffer_Release(&link);
    PyBuffer_Release(&seeds);
    PyBuffer_Release(&out);
    return ret;
}
