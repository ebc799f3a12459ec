/* tanktool._kernels: the walkable surface's passes over its open spans (see _kernels.c):
 * the open spans themselves, the chamfer clearance near the edges only, the levels of
 * the played region's spans.
 *
 *   open_spans(col, smin, smax, walk, out_col, out_floor, out_ceil) -> m
 *       col, smin, smax: int32 (n,) the heightfield's spans; walk: bool (n,); written:
 *       the m walkable spans' column (int64), floor (their top) and ceiling (the next
 *       span's bottom in the column, OPEN above the top one), int32
 *   snap_heights(floor, walk, flat, heights, origin_y, ch, out)
 *       walkable.snap_heights: floor int32 (m,) the open spans'; walk, flat bool (n,) the
 *       heightfield's spans' (the open spans are its walkable ones, in order); heights
 *       float64 sorted; out float64 (m,) written
 *   scatter_layers(level, col, height, clear, per, exists, height_out, span_out, clear_out)
 *       walkable.surface_layers' scatter: level, col int64 (n,); height, clear float64
 *       (n,) (clear: empty when not asked for); outputs over (L * per) nodes, filled
 *       beforehand (False, NaN, -1, 0): bool, float64, int32, float64 (or empty)
 *   level_votes(col, keep, link, level, rounds)
 *       col: int64 (n,) sorted; keep: bool (n,); link: int32 (n, 4); level: int64 (n,)
 *       written: each kept span's rank among the kept spans of its column (-1 where not
 *       kept), then, unless every rank is 0, the voting rounds of
 *       level_stack._vote_rounds: the same moves and the same conflicts.  Returns the
 *       highest rank (-1: nothing kept; 0: one kept span a column, no rounds run)
 *   lift_portals(col, level, link, steps)
 *       col: int64 (n,) sorted; level: int64 (n,) in place (-1 outside the region);
 *       link: int32 (n, 4); level_lift.lift_to_portals
 *   chamfer_near(link, dist, limit, col, nx, ncols)
 *       walkable.chamfer_clearance with the spans' columns: as chamfer() in _kernels.c
 *
 * Why in C: numpy's rounds pass over every kept span to set up (neighbour levels,
 * column ranks, the first active set) and sort (column, level) keys in every round
 * to find the conflicts; here a conflict is a look along the span's own column (a
 * few spans), and a round touches only the active spans.  Spans of a column are
 * adjacent (col sorted), so "the spans of my column" needs no index.
 */
#include "_kernels.h"

#define OPEN_STEPS ((int32_t)1 << 15)  /* span_filters.OPEN */

/* walkable.build_surface's open spans in one pass, where numpy made the ceilings of
 * every span (heightfield.ceiling) and then three masked copies */
PyObject *tanktool_open_spans(PyObject *self, PyObject *args) {
    Py_buffer col, smin, smax, walk, oc, of, oce;
    if (!PyArg_ParseTuple(args, "y*y*y*y*w*w*w*", &col, &smin, &smax, &walk, &oc, &of, &oce)) return NULL;
    const Py_ssize_t n = col.len / 4, m = of.len / 4;
    PyObject *ret = NULL;
    Py_ssize_t k = 0;
    if (!need(&smin, n, 4, "smin") || !need(&smax, n, 4, "smax") || !need(&walk, n, 1, "walk") ||
        !need(&oc, m, 8, "out_col") || !need(&oce, m, 4, "out_ceil"))
        goto done;
    {
        const int32_t *C = col.buf, *lo = smin.buf, *hi = smax.buf;
        const uint8_t *W = walk.buf;
        i64 *outc = oc.buf;
        int32_t *outf = of.buf, *outce = oce.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0; s < n && k < m; ++s) {
            if (!W[s]) continue;
            const int32_t up = s + 1 < n && C[s + 1] == C[s] ? lo[s + 1] : OPEN_STEPS;
            outc[k] = C[s];
            outf[k] = hi[s];
            outce[k++] = up < OPEN_STEPS ? up : OPEN_STEPS;
        }
        Py_END_ALLOW_THREADS
    }
    ret = PyLong_FromSsize_t(k);
done:
    PyBuffer_Release(&col);
    PyBuffer_Release(&smin);
    PyBuffer_Release(&smax);
    PyBuffer_Release(&walk);
    PyBuffer_Release(&oc);
    PyBuffer_Release(&of);
    PyBuffer_Release(&oce);
    return ret;
}

/* walkable.snap_heights in one pass, the same arithmetic (no fused multiply-adds):
 * a flat span's floor is the highest cluster height at or below its top (searchsorted
 * side right, minus one) when that lies within its top voxel step, else the step's
 * middle */
PyObject *tanktool_snap_heights(PyObject *self, PyObject *args) {
    Py_buffer floor_, walk, flat, heights, out;
    double oy, ch;
    if (!PyArg_ParseTuple(args, "y*y*y*y*ddw*", &floor_, &walk, &flat, &heights, &oy, &ch, &out)) return NULL;
    const Py_ssize_t m = floor_.len / 4, n = walk.len, nh = heights.len / 8;
    PyObject *ret = NULL;
    if (!need(&flat, n, 1, "flat") || !need(&out, m, 8, "out")) goto done;
    {
        const int32_t *Fl = floor_.buf;
        const uint8_t *W = walk.buf, *Fh = flat.buf;
        const double *H = heights.buf, half = 0.5 * ch;
        double *O = out.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t s = 0, k = 0; s < n && k < m; ++s) {
            if (!W[s]) continue;
            const double top = oy + (double)Fl[k] * ch;
            double y = top - half;
            if (Fh[s] && nh > 0) {
                const double v = top + 1e-9;
                Py_ssize_t lo = 0, hi = nh;  /* the first height above v */
                while (lo < hi) {
                    const Py_ssize_t mid = lo + (hi - lo) / 2;
                    if (H[mid] <= v) lo = mid + 1; else hi = mid;
                }
                if (lo > 0 && H[lo - 1] >= top - ch - 1e-9) y = H[lo - 1];
            }
            O[k++] = y;
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&floor_);
    PyBuffer_Release(&walk);
    PyBuffer_Release(&flat);
    PyBuffer_Release(&heights);
    PyBuffer_Release(&out);
    return ret;
}

/* walkable.surface_layers: every span of a level written into its node, in one pass
 * where numpy made the node indices a block at a time and scattered four times */
PyObject *tanktool_scatter_layers(PyObject *self, PyObject *args) {
    Py_buffer level, col, height, clear, exists, hout, sout, cout;
    i64 per;
    if (!PyArg_ParseTuple(args, "y*y*y*y*Lw*w*w*w*", &level, &col, &height, &clear, &per, &exists, &hout, &sout,
                          &cout))
        return NULL;
    const Py_ssize_t n = level.len / 8, nodes = exists.len;
    const int with_clear = clear.len > 0;
    PyObject *ret = NULL;
    if (!need(&col, n, 8, "col") || !need(&height, n, 8, "height") || (with_clear && !need(&clear, n, 8, "clear")) ||
        !need(&hout, nodes, 8, "height_out") || !need(&sout, nodes, 4, "span_out") ||
        (with_clear && !need(&cout, nodes, 8, "clear_out")))
        goto done;
    {
        const i64 *Lv = level.buf, *C = col.buf;
        const double *H = height.buf, *Cl = clear.buf;
        uint8_t *E = exists.buf;
        double *Ho = hout.buf, *Co = cout.buf;
        int32_t *So = sout.buf;
        int bad = 0;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t m = 0; m < n; ++m) {
            if (Lv[m] < 0) continue;
            const i64 at = Lv[m] * per + C[m];
            if (at < 0 || at >= nodes) { bad = 1; break; }
            E[at] = 1;
            Ho[at] = H[m];
            So[at] = (int32_t)m;
            if (with_clear) Co[at] = Cl[m];
        }
        Py_END_ALLOW_THREADS
        if (bad) {
            PyErr_SetString(PyExc_ValueError, "scatter_layers: a span beyond the layers");
            goto done;
        }
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&level);
    PyBuffer_Release(&col);
    PyBuffer_Release(&height);
    PyBuffer_Release(&clear);
    PyBuffer_Release(&exists);
    PyBuffer_Release(&hout);
    PyBuffer_Release(&sout);
    PyBuffer_Release(&cout);
    return ret;
}

/* the votes of one span at level cur with neighbour levels nl[4] (-1: none): the
 * level it moves to, or -1 to stay (level_stack._vote_rounds' rule) */
static inline i64 vote(const i64 nl[4], i64 cur) {
    int top = -1, mine = 0;
    i64 best = -1;
    for (int d = 0; d < 4; ++d) {
        int v = -1;
        if (nl[d] >= 0) {
            v = 0;
            for (int e = 0; e < 4; ++e) v += nl[e] == nl[d];
        }
        if (v > top) { top = v; best = nl[d]; }
        else if (v == top && nl[d] > best) best = nl[d];
        mine += nl[d] == cur;
    }
    if (best < 0 || best == cur) return -1;
    if (top > mine || (top == mine && top >= 2 && best > cur)) return best;
    return -1;
}

/* whether another kept span of s's column holds level want: a candidate by its new
 * level (newlv >= 0), any other by its current one (level_stack._level_taken) */
static inline int taken(const i64 *col, const uint8_t *keep, const i64 *lv, const i64 *newlv, Py_ssize_t n,
                        Py_ssize_t s, i64 want) {
    for (int side = -1; side <= 1; side += 2)
        for (Py_ssize_t t = s + side; t >= 0 && t < n && col[t] == col[s]; t += side) {
            if (!keep[t]) continue;
            if ((newlv[t] >= 0 ? newlv[t] : lv[t]) == want) return 1;
        }
    return 0;
}

/* the rounds; act holds the first active spans (nact of them); scratch arrays of n */
static void rounds_of(const i64 *col, const uint8_t *keep, const int32_t *L, i64 *lv, Py_ssize_t n, int rounds,
                      i64 *act, Py_ssize_t nact, i64 *cand, i64 *newlv, uint8_t *flag) {
    for (int r = 0; r < rounds && nact > 0; ++r) {
        Py_ssize_t nc = 0;
        for (Py_ssize_t k = 0; k < nact; ++k) {
            const i64 s = act[k];
            i64 nl[4];
            for (int d = 0; d < 4; ++d) nl[d] = L[4 * s + d] >= 0 ? lv[L[4 * s + d]] : -1;
            const i64 best = vote(nl, lv[s]);
            if (best >= 0) { cand[nc++] = s; newlv[s] = best; }
        }
        if (nc == 0) break;
        /* the conflicts against the levels before the round, then the moves */
        Py_ssize_t nok = 0;
        for (Py_ssize_t k = 0; k < nc; ++k)
            if (!taken(col, keep, lv, newlv, n, cand[k], newlv[cand[k]])) act[nok++] = cand[k];
        for (Py_ssize_t k = 0; k < nok; ++k) lv[act[k]] = newlv[act[k]];
        for (Py_ssize_t k = 0; k < nc; ++k) newlv[cand[k]] = -1;
        if (nok == 0) break;
        /* next round: the spans that moved and their kept neighbours (cand reused) */
        nact = 0;
        for (Py_ssize_t k = 0; k < nok; ++k) {
            const i64 s = act[k];
            if (!flag[s]) { flag[s] = 1; cand[nact++] = s; }
            for (int d = 0; d < 4; ++d) {
                const i64 t = L[4 * s + d];
                if (t >= 0 && keep[t] && !flag[t]) { flag[t] = 1; cand[nact++] = t; }
            }
        }
        for (Py_ssize_t k = 0; k < nact; ++k) { act[k] = cand[k]; flag[cand[k]] = 0; }
    }
}

PyObject *tanktool_level_votes(PyObject *self, PyObject *args) {
    Py_buffer col, keep, link, level;
    int rounds;
    if (!PyArg_ParseTuple(args, "y*y*y*w*i", &col, &keep, &link, &level, &rounds)) return NULL;
    const Py_ssize_t n = col.len / 8;
    PyObject *ret = NULL;
    i64 *act = NULL, *cand = NULL, *newlv = NULL, top = -1;
    uint8_t *flag = NULL;
    if (!need(&keep, n, 1, "keep") || !need(&link, 4 * n, 4, "link") || !need(&level, n, 8, "level")) goto done;
    act = malloc(sizeof(i64) * (n + 1));
    cand = malloc(sizeof(i64) * (n + 1));
    newlv = malloc(sizeof(i64) * (n + 1));
    flag = calloc(n + 1, 1);
    if (!act || !cand || !newlv || !flag) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const i64 *C = col.buf;
        const uint8_t *K = keep.buf;
        const int32_t *L = link.buf;
        i64 *lv = level.buf;
        Py_BEGIN_ALLOW_THREADS
        i64 rank = 0;
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (s == 0 || C[s] != C[s - 1]) rank = 0;
            lv[s] = K[s] ? rank++ : -1;
            if (lv[s] > top) top = lv[s];
            newlv[s] = -1;
        }
        if (top > 0) {
            /* the first active spans: a kept span with a neighbour on another level
             * (or none, or outside the region) */
            Py_ssize_t nact = 0;
            for (Py_ssize_t s = 0; s < n; ++s) {
                if (!K[s]) continue;
                for (int d = 0; d < 4; ++d) {
                    const i64 t = L[4 * s + d];
                    if ((t >= 0 ? lv[t] : -1) != lv[s]) { act[nact++] = s; break; }
                }
            }
            rounds_of(C, K, L, lv, n, rounds, act, nact, cand, newlv, flag);
        }
        Py_END_ALLOW_THREADS
    }
    ret = PyLong_FromLongLong(top);
done:
    free(act);
    free(cand);
    free(newlv);
    free(flag);
    PyBuffer_Release(&col);
    PyBuffer_Release(&keep);
    PyBuffer_Release(&link);
    PyBuffer_Release(&level);
    return ret;
}

/* whether column c holds a span at level want, looking both ways from span p (in
 * column c or next to it): level_lift's held() over its sorted (column, level) keys.
 * want -1 is the key c * L - 1 there, which is column c - 1's level L - 1: kept so. */
static inline int held(const i64 *col, const i64 *lv, Py_ssize_t n, Py_ssize_t p, i64 c, i64 want, i64 L) {
    if (want < 0) {
        c -= 1;
        want = L - 1;
    }
    for (Py_ssize_t t = p; t >= 0 && col[t] >= c; --t)
        if (col[t] == c && lv[t] == want) return 1;
    for (Py_ssize_t t = p + 1; t < n && col[t] <= c; ++t)
        if (col[t] == c && lv[t] == want) return 1;
    return 0;
}

/* the band straight back from the ledged portals (lift_to_portals' steps) */
static void lift_band(const i64 *C, const i64 *lv, const int32_t *K, Py_ssize_t n, i64 L, int steps, i64 *target,
                      int8_t *away, i64 *front, i64 *next, i64 *from) {
    Py_ssize_t nf = 0;
    for (Py_ssize_t s = 0; s < n; ++s)
        if (target[s] >= 0) front[nf++] = s;
    for (int k = 0; k < steps && nf > 0; ++k) {
        /* every step judged on the targets before it, then written in order */
        Py_ssize_t nn = 0;
        for (Py_ssize_t q = 0; q < nf; ++q) {
            const i64 f = front[q], u = K[4 * f + away[f]];
            if (u < 0 || lv[u] != lv[f] || target[u] >= 0 || held(C, lv, n, u, C[u], target[f], L)) continue;
            from[nn] = f;
            next[nn++] = u;
        }
        for (Py_ssize_t q = 0; q < nn; ++q) {
            target[next[q]] = target[from[q]];
            away[next[q]] = away[from[q]];
            front[q] = next[q];
        }
        nf = nn;
    }
}

PyObject *tanktool_lift_portals(PyObject *self, PyObject *args) {
    Py_buffer col, level, link;
    int steps;
    if (!PyArg_ParseTuple(args, "y*w*y*i", &col, &level, &link, &steps)) return NULL;
    const Py_ssize_t n = col.len / 8;
    PyObject *ret = NULL;
    i64 *target = NULL, *front = NULL, *next = NULL, *from = NULL;
    int8_t *away = NULL;
    if (!need(&level, n, 8, "level") || !need(&link, 4 * n, 4, "link")) goto done;
    target = malloc(sizeof(i64) * (n + 1));
    front = malloc(sizeof(i64) * (n + 1));
    next = malloc(sizeof(i64) * (n + 1));
    from = malloc(sizeof(i64) * (n + 1));
    away = malloc(n + 1);
    if (!target || !front || !next || !from || !away) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const i64 *C = col.buf;
        const int32_t *K = link.buf;
        i64 *lv = level.buf;
        Py_BEGIN_ALLOW_THREADS
        i64 L = 0;
        for (Py_ssize_t s = 0; s < n; ++s) {
            if (lv[s] + 1 > L) L = lv[s] + 1;
            target[s] = -1;
            away[s] = 0;
        }
        if (L > 0) {
            /* direction by direction, the last that finds a ledged portal wins */
            for (int d = 0; d < 4; ++d)
                for (Py_ssize_t s = 0; s < n; ++s) {
                    const i64 t = K[4 * s + d];
                    if (lv[s] < 0 || t < 0 || lv[t] == lv[s]) continue;
                    if (held(C, lv, n, t, C[t], lv[s], L) && !held(C, lv, n, s, C[s], lv[t], L)) {
                        target[s] = lv[t];
                        away[s] = (int8_t)((d + 2) % 4);
                    }
                }
            lift_band(C, lv, K, n, L, steps, target, away, front, next, from);
            /* two spans of one column sent to the same level: neither moves (judged on
             * the targets alone, so moving as we go changes nothing) */
            for (Py_ssize_t s = 0; s < n; ++s) {
                if (target[s] < 0) continue;
                int twice = 0;
                for (int side = -1; side <= 1 && !twice; side += 2)
                    for (Py_ssize_t t = s + side; t >= 0 && t < n && C[t] == C[s]; t += side)
                        if (target[t] == target[s]) { twice = 1; break; }
                if (!twice) lv[s] = target[s];
            }
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    free(target);
    free(front);
    free(next);
    free(from);
    free(away);
    PyBuffer_Release(&col);
    PyBuffer_Release(&level);
    PyBuffer_Release(&link);
    return ret;
}

/* ------------------------------------------------------------------ clearance */

/* chamfer() over the links of walkable.link_spans, whose reads (a straight step, a
 * diagonal one) all lie in the 3 x 3 columns around a span's own: a sweep relaxes only
 * the spans of columns next to one that changed in this sweep or the one before (a
 * stamp a column, 1 byte; and a stamp a row, to pass over quiet rows whole), where
 * chamfer() relaxes every span in every sweep.  The same fixed point: the shortest
 * chamfer paths, unique with positive steps, and a span is relaxed again after every
 * change it reads.  Sweep 0 "changes" the spans whose start is not the limit or that
 * lack a link (the edge: the only spans below the limit before the sweeps, and the
 * only ones read through the sentinel).  Stamps cycle 1..255: an old one read as new
 * costs a relax, never a miss. */
static inline int recent(const uint8_t *r, uint8_t prev, uint8_t cur) {
    return r[0] == prev || r[0] == cur || r[1] == prev || r[1] == cur || r[2] == prev || r[2] == cur;
}

/* one sweep over the rows (forward or back); whether anything changed */
static int sweep_near(const int32_t *L, int32_t *D, const i64 *C, const i64 *rs, i64 nz, i64 nx, uint8_t *stamp,
                      uint8_t *rstamp, uint8_t prev, uint8_t cur, int back) {
    int changed = 0;
    for (i64 q = 0; q < nz; ++q) {
        const i64 r = back ? nz - 1 - q : q;
        if (!recent(rstamp + r, prev, cur)) continue;  /* rows r - 1 .. r + 1 (padded by one) */
        for (i64 p = 0; p < rs[r + 1] - rs[r]; ++p) {
            const i64 s = back ? rs[r + 1] - 1 - p : rs[r] + p;
            const i64 c = C[s] + nx + 1;
            /* a column's spans are adjacent: whether it is near a change could be found
             * once a column, but a change in it makes it near, so each span asks */
            if (!recent(stamp + c - nx - 1, prev, cur) && !recent(stamp + c - 1, prev, cur) &&
                !recent(stamp + c + nx - 1, prev, cur))
                continue;
            const int32_t v = relax(L, D, s, D[s]);
            if (v < D[s]) {
                D[s] = v;
                changed = 1;
                stamp[c] = cur;
                rstamp[r + 1] = cur;
            }
        }
    }
    return changed;
}

PyObject *tanktool_chamfer_near(PyObject *self, PyObject *args) {
    Py_buffer link, dist, col;
    int limit;
    i64 nx, ncols;
    if (!PyArg_ParseTuple(args, "y*w*iy*LL", &link, &dist, &limit, &col, &nx, &ncols)) return NULL;
    Py_ssize_t n = dist.len / 4;
    const i64 nz = nx > 0 ? ncols / nx : 0;
    PyObject *ret = NULL;
    uint8_t *stamp = NULL, *rstamp = NULL;
    i64 *rs = NULL;
    if (!need(&link, 4 * n, 4, "link") || !need(&col, n, 8, "col")) goto done;
    stamp = calloc((size_t)(ncols + 2 * nx + 2), 1);  /* padded: column c at c + nx + 1 */
    rstamp = calloc((size_t)(nz + 2), 1);             /* row r at r + 1 */
    rs = malloc(sizeof(i64) * (size_t)(nz + 1));      /* the first span of each row */
    if (stamp == NULL || rstamp == NULL || rs == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    {
        const int32_t *L = link.buf;
        const i64 *C = col.buf;
        int32_t *D = dist.buf;
        Py_BEGIN_ALLOW_THREADS
        for (i64 r = 0, s = 0; r <= nz; ++r) {
            while (s < n && C[s] < r * nx) ++s;
            rs[r] = s;
        }
        for (i64 r = 0; r < nz; ++r)
            for (i64 s = rs[r]; s < rs[r + 1]; ++s) {
                const int32_t *l = L + 4 * s;
                if (D[s] != limit || l[0] < 0 || l[1] < 0 || l[2] < 0 || l[3] < 0) {
                    stamp[C[s] + nx + 1] = 1;
                    rstamp[r + 1] = 1;
                }
            }
        uint8_t prev, cur = 1;
        for (int k = 0, changed = 1; changed; ++k) {
            prev = cur;
            cur = cur == 255 ? 1 : cur + 1;
            changed = sweep_near(L, D, C, rs, nz, nx, stamp, rstamp, prev, cur, k % 2);
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    free(stamp);
    free(rstamp);
    free(rs);
    PyBuffer_Release(&link);
    PyBuffer_Release(&dist);
    PyBuffer_Release(&col);
    return ret;
}

/* level_walls._flat_floor_of: each flat cell's flat index and the model floor its
 * span's height rounds up from, in one pass where numpy took flatnonzero, a gather,
 * searchsorted and where (hix: ~0.13 s).  flat_cells bool (N,); span_of int32 (N,);
 * span_y float64; flat_h float64 sorted; out_idx int32 (m,), out_pos int32 (m,), m the
 * flat cells: pos the highest floor at or below hy + 1e-6 (searchsorted side right,
 * minus one) when hy - that floor <= cell_h + 1e-6, else -1 */
PyObject *tanktool_flat_floor_of(PyObject *self, PyObject *args) {
    Py_buffer cells, span_of, span_y, flat_h, oi, op;
    double cell_h;
    if (!PyArg_ParseTuple(args, "y*y*y*y*dw*w*", &cells, &span_of, &span_y, &flat_h, &cell_h, &oi, &op))
        return NULL;
    const Py_ssize_t n = cells.len, m = oi.len / 4, nh = flat_h.len / 8, ns = span_y.len / 8;
    PyObject *ret = NULL;
    int bad = 0;
    if (!need(&span_of, n, 4, "span_of") || !need(&op, m, 4, "out_pos")) goto done;
    {
        const uint8_t *C = cells.buf;
        const int32_t *S = span_of.buf;
        const double *Y = span_y.buf, *H = flat_h.buf, tol = cell_h + 1e-6;
        int32_t *I = oi.buf, *P = op.buf;
        Py_ssize_t k = 0, lo = 0;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t c = 0; c < n; ++c) {
            if (!C[c]) continue;
            if (k >= m || S[c] < 0 || S[c] >= ns) { bad = 1; break; }
            const double hy = Y[S[c]], v = hy + 1e-6;
            /* the first floor above v: the last cell's when it still is (neighbours
             * mostly stand on one floor), else a binary search */
            if (!((lo == 0 || H[lo - 1] <= v) && (lo == nh || H[lo] > v))) {
                Py_ssize_t hi = nh;
                lo = 0;
                while (lo < hi) {
                    const Py_ssize_t mid = lo + (hi - lo) / 2;
                    if (H[mid] <= v) lo = mid + 1; else hi = mid;
                }
            }
            /* numpy: p = lo - 1; ok = p >= 0 and hy - H[max(p, 0)] <= tol */
            I[k] = (int32_t)c;
            P[k++] = (lo > 0 && hy - H[lo - 1] <= tol) ? (int32_t)(lo - 1) : -1;
        }
        Py_END_ALLOW_THREADS
        if (!bad && k != m) bad = 1;
    }
    if (bad) {
        PyErr_SetString(PyExc_ValueError, "flat_floor_of: out arrays do not match the flat cells");
        goto done;
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&cells);
    PyBuffer_Release(&span_of);
    PyBuffer_Release(&span_y);
    PyBuffer_Release(&flat_h);
    PyBuffer_Release(&oi);
    PyBuffer_Release(&op);
    return ret;
}
