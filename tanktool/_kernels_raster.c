/* tanktool/_kernels_raster.c: heightfield.rasterize's loops in C (see _kernels.c):
 * the spans of each (triangle, cell) pair, the same arithmetic in the same order as
 * the numpy code, so that the spans are identical; and heightfield._merge's, the
 * pieces of each column merged into spans. */
#include "_kernels.h"

/* ------------------------------------------------------------------ rasterising */

/* growable int64 columns of the rasteriser's output; with walk and flat (raster_merge)
 * one packed key a piece instead (column << 34 | bottom << 18 | top << 2 | walkable << 1
 * | flat: the key heightfield._merge sorts), 8 bytes a piece where the columns take 32 */
typedef struct {
    i64 *col, *tri, *smin, *smax;
    Py_ssize_t n, cap;
    const uint8_t *walk, *flat;  /* per triangle */
} Cells;

static int cells_push(Cells *c, i64 col, i64 tri, i64 smin, i64 smax) {
    if (c->walk != NULL) {
        if (c->n == c->cap) {
            Py_ssize_t cap = c->cap ? 2 * c->cap : 4096;
            i64 *a = realloc(c->col, cap * 8);
            if (a == NULL) return 0;
            c->col = a;
            c->cap = cap;
        }
        c->col[c->n++] = (col << 34) | (smin << 18) | (smax << 2) | ((i64)(c->walk[tri] != 0) << 1) |
                         (i64)(c->flat[tri] != 0);
        return 1;
    }
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

/* ------------------------------------------------------------------ merging */

/* heightfield._merge (numpy) over the sorted packed keys (column << 34 | bottom << 18 | top << 2
 * | walkable << 1 | flat): the overlapping or touching pieces of a column become one
 * span; its flags are those of the pieces whose tops lie within thr of its top (and
 * top_walk: of the pieces reaching its very top).  Writes the spans into the six
 * output arrays (at most as long as the keys) and returns how many. */
static Py_ssize_t merge_keys(const i64 *K, Py_ssize_t n, i64 thr, i64 *C, i64 *S0, i64 *S1, char *W, char *F,
                             char *T) {
    Py_ssize_t m = 0, a = 0;
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
    return m;
}

/* the six output arrays of the merges, checked against n items */
static int merge_outputs(Py_buffer *o, Py_ssize_t n) {
    return need(&o[0], n, 8, "col") && need(&o[1], n, 8, "smin") && need(&o[2], n, 8, "smax") &&
           need(&o[3], n, 1, "walk") && need(&o[4], n, 1, "flat") && need(&o[5], n, 1, "top_walk");
}

static int cmp_i64(const void *a, const void *b) {
    const i64 x = *(const i64 *)a, y = *(const i64 *)b;
    return (x > y) - (x < y);
}

/* the packed keys K (n) in sorted order into S, without sorting them all: counted into
 * their columns (over the columns' range only: a band of a tiled build), then each
 * column's few keys sorted in place.  The array np.sort gives, so the same spans */
static int sort_packed(const i64 *K, Py_ssize_t n, i64 *S) {
    if (n == 0) return 1;
    i64 cmin = K[0] >> 34, cmax = cmin;
    for (Py_ssize_t s = 1; s < n; ++s) {
        const i64 c = K[s] >> 34;
        if (c < cmin) cmin = c;
        if (c > cmax) cmax = c;
    }
    const i64 range = cmax - cmin + 1;
    i64 *start = calloc((size_t)range + 1, sizeof(i64));
    if (start == NULL) return 0;
    for (Py_ssize_t s = 0; s < n; ++s) start[(K[s] >> 34) - cmin + 1]++;
    for (i64 c = 0; c < range; ++c) start[c + 1] += start[c];
    for (Py_ssize_t s = 0; s < n; ++s) S[start[(K[s] >> 34) - cmin]++] = K[s];  /* start[c]: the column's end after */
    for (i64 c = 0, a = 0; c < range; ++c) {
        const i64 b = start[c];  /* the column's keys are S[a:b] */
        if (b - a > 24) {
            qsort(S + a, (size_t)(b - a), sizeof(i64), cmp_i64);
        } else {
            for (i64 k = a + 1; k < b; ++k) {  /* insertion: a column holds a few pieces */
                const i64 v = S[k];
                i64 q = k - 1;
                while (q >= a && S[q] > v) {
                    S[q + 1] = S[q];
                    --q;
                }
                S[q + 1] = v;
            }
        }
        a = b;
    }
    free(start);
    return 1;
}

static PyObject *as_array(const void *a, Py_ssize_t bytes) {
    return PyByteArray_FromStringAndSize(bytes ? (const char *)a : "", bytes);
}

/* the triangles in order of their lowest vertex (counted by cell heights): a column's
 * pieces then come mostly bottom first, and sorting each column's keys (sort_packed's
 * insertion) moves little and mispredicts little: raster_merge on Recast's dungeon
 * 6.4 -> 6.0 ms of CPU.  Only the order of the pieces changes, not the pieces, so not the spans */
static Py_ssize_t *lowest_first(const double *T, Py_ssize_t n, double ch, i64 maxh) {
    Py_ssize_t *order = malloc(sizeof(Py_ssize_t) * (size_t)(n + 1));
    i64 *start = calloc((size_t)maxh + 3, sizeof(i64));
    int32_t *bin = malloc(sizeof(int32_t) * (size_t)(n + 1));
    if (order == NULL || start == NULL || bin == NULL) {
        free(order);
        free(start);
        free(bin);
        return NULL;
    }
    for (Py_ssize_t t = 0; t < n; ++t) {
        const double *y = T + 9 * t + 6, lo = mind(mind(y[0], y[1]), y[2]) / ch;
        const i64 b = lo >= 0 ? (lo < (double)maxh ? (i64)lo : maxh) : 0;  /* NaN: 0 */
        bin[t] = (int32_t)b;
        start[b + 1]++;
    }
    for (i64 b = 0; b <= maxh; ++b) start[b + 1] += start[b];
    for (Py_ssize_t t = 0; t < n; ++t) order[start[bin[t]]++] = t;
    free(start);
    free(bin);
    return order;
}

/* heightfield.rasterize then _merge, for every triangle in one call: the pieces as
 * packed keys, counted into columns, merged.  The same pieces (each triangle's, as
 * raster() makes them; steep per triangle) and so, sorted, the same spans.  Returns
 * (pieces, col, smin, smax, walk, flat, top_walk): a count, then bytearrays of int64
 * and bool. */
PyObject *tanktool_raster_merge(PyObject *self, PyObject *args) {
    Py_buffer tri, abc, steep, walk, flat;
    i64 nz, nx, maxh, row_lo, row_hi, thr;
    double ch;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*LLdLLLL", &tri, &abc, &steep, &walk, &flat, &nz, &nx, &ch, &maxh, &row_lo,
                          &row_hi, &thr))
        return NULL;
    if (row_lo < 0) row_lo = 0;
    if (row_hi > nz) row_hi = nz;
    const Py_ssize_t n = tri.len / (9 * 8);
    PyObject *ret = NULL;
    Cells out = {0};
    Scratch buf = {0};
    i64 *S = NULL, *C = NULL;
    char *F = NULL;
    Py_ssize_t m = 0;
    int ok = 1;
    if (!need(&tri, 9 * n, 8, "tri") || !need(&abc, 3 * n, 8, "abc") || !need(&steep, n, 1, "steep") ||
        !need(&walk, n, 1, "walk") || !need(&flat, n, 1, "flat"))
        goto done;
    out.walk = walk.buf;
    out.flat = flat.buf;
    {
        const double *T = tri.buf, *P = abc.buf;
        const uint8_t *St = steep.buf;
        Py_BEGIN_ALLOW_THREADS
        Py_ssize_t *order = lowest_first(T, n, ch, maxh);
        ok = order != NULL;
        for (Py_ssize_t q = 0; q < n && ok; ++q) {
            const Py_ssize_t t = order[q];
            const double *v = T + 9 * t; /* x0 x1 x2 z0 z1 z2 y0 y1 y2 */
            ok = raster_one(&out, &buf, St[t] != 0, t, v, v + 3, v + 6, P[3 * t], P[3 * t + 1], P[3 * t + 2],
                            row_lo, row_hi, nx, ch, maxh);
        }
        free(order);
        /* the sorted keys, then the spans: col, smin, smax (3 x int64) and walk, flat,
         * top_walk (3 x bool) in one block as long as the pieces */
        S = ok ? malloc(sizeof(i64) * (size_t)(out.n + 1)) : NULL;
        C = S ? malloc((3 * sizeof(i64) + 3) * (size_t)(out.n + 1)) : NULL;
        ok = C != NULL && sort_packed(out.col, out.n, S);
        if (ok) {
            F = (char *)(C + 3 * (out.n + 1));
            m = merge_keys(S, out.n, thr, C, C + (out.n + 1), C + 2 * (out.n + 1), F, F + (out.n + 1),
                           F + 2 * (out.n + 1));
        }
        Py_END_ALLOW_THREADS
    }
    if (!ok) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const Py_ssize_t w = out.n + 1;
        ret = Py_BuildValue("(nNNNNNN)", out.n, as_array(C, m * 8), as_array(C + w, m * 8), as_array(C + 2 * w, m * 8),
                            as_array(F, m), as_array(F + w, m), as_array(F + 2 * w, m));
    }
done:
    free(buf.v);
    free(out.col);
    free(S);
    free(C);
    PyBuffer_Release(&tri);
    PyBuffer_Release(&abc);
    PyBuffer_Release(&steep);
    PyBuffer_Release(&walk);
    PyBuffer_Release(&flat);
    return ret;
}
