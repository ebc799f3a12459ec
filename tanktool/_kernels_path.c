/* nav/path.py's astar_layered in C: (see _kernels.c)
 *
 *   astar_layered(valid, link, L, nz, nx, start, goal) -> [node, ...] (flat indices, start
 *       first; [] when there is no way)
 *       valid: bool (L, nz, nx); link: int8 (L, nz, nx, 4); start, goal: valid flat nodes
 *
 * The same search as the Python one: the moves of layered_moves (four straight steps
 * along the links costing 1, four diagonal ones costing sqrt(2) where both ways round
 * reach the same node), the octile heuristic over (i, j), the open list ordered by
 * (f, g, node) as Python's heap of tuples is -- the order is total, so the nodes come
 * off it in the same order and the path is the same one.  Node state is kept in
 * arrays as large as the grid, calloc'd: only the pages a search touches are paid for.
 */
#include "_kernels.h"

typedef struct {
    double f, g;
    i64 m;
} Entry;

static inline int before(const Entry *a, const Entry *b) {
    if (a->f != b->f) return a->f < b->f;
    if (a->g != b->g) return a->g < b->g;
    return a->m < b->m;
}

typedef struct {
    Entry *e;
    i64 n, cap;
} Heap;

static int heap_push(Heap *h, Entry x) {
    if (h->n == h->cap) {
        i64 cap = h->cap ? 2 * h->cap : 1024;
        Entry *e = realloc(h->e, (size_t)cap * sizeof(Entry));
        if (e == NULL) return 0;
        h->e = e, h->cap = cap;
    }
    i64 k = h->n++;
    while (k > 0) {
        const i64 p = (k - 1) / 2;
        if (!before(&x, &h->e[p])) break;
        h->e[k] = h->e[p];
        k = p;
    }
    h->e[k] = x;
    return 1;
}

static Entry heap_pop(Heap *h) {
    Entry top = h->e[0], x = h->e[--h->n];
    i64 k = 0;
    for (;;) {
        i64 c = 2 * k + 1;
        if (c >= h->n) break;
        if (c + 1 < h->n && before(&h->e[c + 1], &h->e[c])) ++c;
        if (!before(&h->e[c], &x)) break;
        h->e[k] = h->e[c];
        k = c;
    }
    if (h->n > 0) h->e[k] = x;
    return top;
}

static const int PDI[4] = {0, 1, 0, -1}, PDJ[4] = {1, 0, -1, 0};

typedef struct {
    const uint8_t *valid;
    const int8_t *link;
    i64 nz, nx, per;
} Grid;

/* _LazyMoves.straight: the target of straight move d from node m (-1: none) */
static inline i64 straight(const Grid *g, i64 m, int d) {
    const i64 r = m % g->per, i = r / g->nx + PDI[d], j = r % g->nx + PDJ[d];
    const int t = g->link[4 * m + d];
    if (t < 0 || i < 0 || i >= g->nz || j < 0 || j >= g->nx) return -1;
    const i64 n = (i64)t * g->per + i * g->nx + j;
    return g->valid[n] ? n : -1;
}

/* _LazyMoves' row of node m: four straight targets, then four diagonal ones */
static void moves(const Grid *g, i64 m, i64 out[8]) {
    if (!g->valid[m]) {
        for (int k = 0; k < 8; ++k) out[k] = -1;
        return;
    }
    for (int d = 0; d < 4; ++d) out[d] = straight(g, m, d);
    for (int d = 0; d < 4; ++d) {
        const int e = (d + 1) & 3;
        const i64 via_d = out[d] >= 0 ? straight(g, out[d], e) : -1;
        const i64 via_e = out[e] >= 0 ? straight(g, out[e], d) : -1;
        out[4 + d] = via_d >= 0 && via_d == via_e ? via_d : -1;
    }
}

/* astar_layered's h: the octile distance over (i, j) to the goal (gi, gj); Python's
 * int + float: (di + dj) + k2 * min(di, dj) */
static inline double octile(i64 m, i64 per, i64 nx, i64 gi, i64 gj, double k2) {
    const i64 r = m % per, di = llabs(r / nx - gi), dj = llabs(r % nx - gj);
    return (double)(di + dj) + k2 * (double)(di < dj ? di : dj);
}

PyObject *tanktool_astar_layered(PyObject *self, PyObject *args) {
    Py_buffer vb, kb;
    Py_ssize_t L, nz, nx, start, goal;
    if (!PyArg_ParseTuple(args, "y*y*nnnnn", &vb, &kb, &L, &nz, &nx, &start, &goal)) return NULL;
    PyObject *ret = NULL;
    const i64 per = (i64)nz * nx, n = (i64)L * per;
    uint8_t *state = NULL;   /* 0 unseen, 1 seen (best, came set), 2 closed */
    double *best = NULL;
    i64 *came = NULL;
    Heap heap = {NULL, 0, 0};
    if (!need(&vb, n, 1, "valid") || !need(&kb, 4 * n, 1, "link")) goto done;
    if (start < 0 || start >= n || goal < 0 || goal >= n) {
        PyErr_SetString(PyExc_ValueError, "astar_layered: a node off the grid");
        goto done;
    }
    state = calloc((size_t)n, 1);
    best = calloc((size_t)n, sizeof(double));
    came = calloc((size_t)n, sizeof(i64));
    if (state == NULL || best == NULL || came == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const Grid g = {vb.buf, kb.buf, nz, nx, per};
        const double SQRT2 = sqrt(2.0), k2 = SQRT2 - 2.0;
        const double cost[8] = {1.0, 1.0, 1.0, 1.0, SQRT2, SQRT2, SQRT2, SQRT2};
        const i64 gi = (goal % per) / nx, gj = goal % nx;
        int found = 0, oom = 0;
        Py_BEGIN_ALLOW_THREADS
        state[start] = 1;
        best[start] = 0.0;
        came[start] = -1;
        if (!heap_push(&heap, (Entry){octile(start, per, nx, gi, gj, k2), 0.0, start})) oom = 1;
        while (!oom && heap.n > 0) {
            const Entry top = heap_pop(&heap);
            const i64 m = top.m;
            if (m == goal) {
                found = 1;
                break;
            }
            if (state[m] == 2) continue;
            state[m] = 2;
            i64 t[8];
            moves(&g, m, t);
            for (int k = 0; k < 8; ++k) {
                if (t[k] < 0 || state[t[k]] == 2) continue;
                const double ng = top.g + cost[k];
                if (state[t[k]] == 0 || ng < best[t[k]]) {
                    state[t[k]] = 1;
                    best[t[k]] = ng;
                    came[t[k]] = m;
                    if (!heap_push(&heap, (Entry){ng + octile(t[k], per, nx, gi, gj, k2), ng, t[k]})) {
                        oom = 1;
                        break;
                    }
                }
            }
        }
        Py_END_ALLOW_THREADS
        if (oom) {
            PyErr_NoMemory();
            goto done;
        }
        ret = PyList_New(0);
        if (ret == NULL || !found) goto done;
        /* goal back to start, then reversed: Python's came chain */
        for (i64 m = goal; m >= 0; m = (m == start ? -1 : came[m])) {
            PyObject *v = PyLong_FromLongLong(m);
            if (v == NULL || PyList_Append(ret, v) < 0) {
                Py_XDECREF(v);
                Py_CLEAR(ret);
                goto done;
            }
            Py_DECREF(v);
        }
        if (PyList_Reverse(ret) < 0) Py_CLEAR(ret);
    }
done:
    free(state);
    free(best);
    free(came);
    free(heap.e);
    PyBuffer_Release(&vb);
    PyBuffer_Release(&kb);
    return ret;
}
