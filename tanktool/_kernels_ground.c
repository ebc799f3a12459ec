/* The ground under a tank (sim/ground.py's Ground.tilt, height, follow), in C: (see _kernels.c)
 *
 *   ground_tilt(h, flat, L, nz, nx, ox, oz, cell, climb, reach, level, x, z, c, s, half_length,
 *               half_width) -> (y, pitch, roll), or None where Python must answer
 *       h: float64 (L, nz, nx) node heights (not finite: no node); flat: bool (L, nz, nx) level
 *       ground (Ground._level_ground); reach: FLAT_CELLS * cell
 *   ground_height(h, L, nz, nx, ox, oz, cell, climb, level, x, z) -> float, or None
 *   ground_follow(link, L, nz, nx, level, i0, j0, i1, j1) -> level (-1: no way), or None
 *       link: int8 (L, nz, nx, 4), the ground's links
 *   grid_walk(link, ok, rows, cols, out, L, nz, nx, k)   (layers._walked: the agents' grid)
 *   grade_cut(link, heights, L, NZ, NX, most)   (layers._cut_grade, in place)
 *   solid_visible(solid, points, out, nz, nx, ny, ox, oz, y0, cs, ch, margin, step, max_range)
 *       (SolidField.visible: the agents' sight table)
 *
 * Ground.tilt's arithmetic one operation at a time (no fused multiply-adds: built with
 * -ffp-contract=off), Python's float floor division in cell_of, its atan2 (libm's), so
 * the values are the Python code's to the bit (tests/test_match_lean.py).  None for what
 * the Python code would not answer with numbers (a NaN coordinate, a level with no node
 * where it reads one): it runs then and says what it says.
 */
#include "_kernels.h"

typedef struct {
    const double *h;
    const uint8_t *flat;
    i64 L, nz, nx;
    double ox, oz, cell, climb;
} Ground;

/* Python's float // (CPython's _float_div_mod), as an index clamped into [0, n) */
static i64 floor_div_clamped(double vx, double wx, i64 n) {
    double mod = fmod(vx, wx), div = (vx - mod) / wx, fd;
    if (mod) {
        if ((wx < 0) != (mod < 0)) div -= 1.0;
    }
    if (div) {
        fd = floor(div);
        if (div - fd > 0.5) fd += 1.0;
    } else {
        fd = 0.0;
    }
    if (fd < 0.0) return 0;
    if (fd >= (double)n) return n - 1;
    return (i64)fd;
}

static inline double H(const Ground *g, i64 lv, i64 i, i64 j) { return g->h[(lv * g->nz + i) * g->nx + j]; }

/* Ground.locate(x, z) without a height: the lowest level with a node in the cell, -1 */
static i64 lowest(const Ground *g, i64 i, i64 j) {
    for (i64 lv = 0; lv < g->L; ++lv)
        if (isfinite(H(g, lv, i, j))) return lv;
    return -1;
}

/* Ground._nearest: the node height at (i, j) nearest y within the climb (NaN: none) */
static double nearest(const Ground *g, i64 i, i64 j, double y) {
    if (!(0 <= i && i < g->nz && 0 <= j && j < g->nx)) return NAN;
    double best = NAN, best_d = g->climb + 1e-9;
    for (i64 lv = 0; lv < g->L; ++lv) {
        const double hv = H(g, lv, i, j);
        if (isfinite(hv) && fabs(hv - y) <= best_d) {
            best = hv;
            best_d = fabs(hv - y);
        }
    }
    return best;
}

/* Ground.height; returns 0 and leaves *out when Python must answer */
static int height(const Ground *g, double x, double z, i64 level, double *out) {
    double u = (x - g->ox) / g->cell, w = (z - g->oz) / g->cell;
    i64 i, j;
    if (!(fabs(u) < 1e15 && fabs(w) < 1e15)) return 0;   /* far off the grid: Python's */
    if (u >= 0.0 && w >= 0.0 && u < (double)g->nx && w < (double)g->nz) {
        j = (i64)u;   /* int(u): truncation, u >= 0 */
        i = (i64)w;
    } else {
        j = floor_div_clamped(x - g->ox, g->cell, g->nx);
        i = floor_div_clamped(z - g->oz, g->cell, g->nz);
    }
    double hc = (0 <= level && level < g->L) ? H(g, level, i, j) : NAN;
    if (!isfinite(hc)) {
        /* locate(x, z) reads cell_of(x, z), which may differ from (i, j) by rounding:
           then Python's answer */
        const i64 ci = floor_div_clamped(z - g->oz, g->cell, g->nz), cj = floor_div_clamped(x - g->ox, g->cell, g->nx);
        if (ci != i || cj != j) return 0;
        const i64 lv = lowest(g, i, j);
        if (lv < 0) {
            *out = 0.0;
            return 1;
        }
        level = lv;
        hc = H(g, lv, i, j);
    }
    u -= 0.5;
    w -= 0.5;
    const double fj0 = floor(u), fi0 = floor(w);
    const double fu = u - fj0, fw = w - fi0;
    const i64 j0 = (i64)fj0, i0 = (i64)fi0;
    if (0 <= i0 && i0 + 1 < g->nz && 0 <= j0 && j0 + 1 < g->nx) {
        const double a = H(g, level, i0, j0), b = H(g, level, i0, j0 + 1);
        const double c = H(g, level, i0 + 1, j0), d = H(g, level, i0 + 1, j0 + 1);
        if (isfinite(a) && isfinite(b) && isfinite(c) && isfinite(d)) {
            const double lim = g->climb;
            if (fabs(a - hc) <= lim && fabs(b - hc) <= lim && fabs(c - hc) <= lim && fabs(d - hc) <= lim) {
                *out = (a * (1.0 - fu) + b * fu) * (1.0 - fw) + (c * (1.0 - fu) + d * fu) * fw;
                return 1;
            }
        }
    }
    double total = 0.0, acc = 0.0;
    const i64 is[2] = {i0, i0 + 1}, js[2] = {j0, j0 + 1};
    const double wis[2] = {1.0 - fw, fw}, wjs[2] = {1.0 - fu, fu};
    for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q) {
            const double wgt = wis[p] * wjs[q];
            if (wgt <= 0.0) continue;
            const double hv = nearest(g, is[p], js[q], hc);
            if (!isnan(hv)) {
                acc += wgt * hv;
                total += wgt;
            }
        }
    *out = total > 0.0 ? acc / total : hc;
    return 1;
}

/* sim/ground.py's supported: an end of the hull over ground more than drop below its
   centre y is not under it; the hull lies on the other end's slope (both: level) */
static void supported(double y, double *ha, double *hb, double drop) {
    const double low = y - drop;
    if (*ha < low) {
        if (*hb < low) {
            *ha = y;
            *hb = y;
        } else {
            *ha = y + (y - *hb);
        }
    } else if (*hb < low) {
        *hb = y + (y - *ha);
    }
}

PyObject *tanktool_ground_tilt(PyObject *self, PyObject *args) {
    Py_buffer hb, fb;
    Ground g;
    double reach, x, z, c, s, hl, hw;
    Py_ssize_t L, nz, nx, level;
    if (!PyArg_ParseTuple(args, "y*y*nnndddddndddddd", &hb, &fb, &L, &nz, &nx, &g.ox, &g.oz, &g.cell, &g.climb,
                          &reach, &level, &x, &z, &c, &s, &hl, &hw))
        return NULL;
    PyObject *ret = NULL;
    const i64 n = (i64)L * nz * nx;
    if (!need(&hb, n, 8, "h") || !need(&fb, n, 1, "flat")) goto done;
    g.h = hb.buf;
    g.flat = fb.buf;
    g.L = L, g.nz = nz, g.nx = nx;
    if (!(isfinite(x) && isfinite(z) && isfinite(c) && isfinite(s) && isfinite(hl) && isfinite(hw))) {
        ret = Py_None;
        Py_INCREF(ret);
        goto done;
    }
    {
        const i64 j = floor_div_clamped(x - g.ox, g.cell, nx), i = floor_div_clamped(z - g.oz, g.cell, nz);
        if (0 <= level && level < L && g.flat[(level * nz + i) * nx + j] && hl <= reach && hw <= reach) {
            ret = Py_BuildValue("(ddd)", H(&g, level, i, j), 0.0, 0.0);
            goto done;
        }
        double y, hf, hbk, hr, hlft;
        if (!height(&g, x, z, level, &y) || !height(&g, x + c * hl, z + s * hl, level, &hf) ||
            !height(&g, x - c * hl, z - s * hl, level, &hbk) || !height(&g, x - s * hw, z + c * hw, level, &hr) ||
            !height(&g, x + s * hw, z - c * hw, level, &hlft)) {
            ret = Py_None;
            Py_INCREF(ret);
            goto done;
        }
        supported(y, &hf, &hbk, g.climb + hl);
        supported(y, &hlft, &hr, g.climb + hw);
        const double pitch = hl > 0 ? atan2(hf - hbk, 2.0 * hl) : 0.0;
        const double roll = hw > 0 ? atan2(hlft - hr, 2.0 * hw) : 0.0;
        ret = Py_BuildValue("(ddd)", y, pitch, roll);
    }
done:
    PyBuffer_Release(&hb);
    PyBuffer_Release(&fb);
    return ret;
}

/* Ground.height(x, z, level), or None where Python must answer */
PyObject *tanktool_ground_height(PyObject *self, PyObject *args) {
    Py_buffer hb;
    Ground g;
    double x, z, y;
    Py_ssize_t L, nz, nx, level;
    if (!PyArg_ParseTuple(args, "y*nnnddddndd", &hb, &L, &nz, &nx, &g.ox, &g.oz, &g.cell, &g.climb, &level, &x, &z))
        return NULL;
    PyObject *ret = NULL;
    if (!need(&hb, (i64)L * nz * nx, 8, "h")) goto done;
    g.h = hb.buf;
    g.flat = NULL;
    g.L = L, g.nz = nz, g.nx = nx;
    if (isfinite(x) && isfinite(z) && height(&g, x, z, level, &y)) {
        ret = PyFloat_FromDouble(y);
    } else {
        ret = Py_None;
        Py_INCREF(ret);
    }
done:
    PyBuffer_Release(&hb);
    return ret;
}

/* the steps (di, dj) of the links +x, +z, -x, -z */
static const int DI_G[4] = {0, 1, 0, -1}, DJ_G[4] = {1, 0, -1, 0};

/* the link of node (lv, i, j) in direction d: a level, -1 none */
static inline int step_link(const int8_t *K, i64 nz, i64 nx, i64 lv, i64 i, i64 j, int d) {
    return K[((lv * nz + i) * nx + j) * 4 + d];
}

/* Ground.follow for cells one step apart (a straight or diagonal move); i1, j1 in the grid */
static i64 follow1(const int8_t *K, i64 L, i64 nz, i64 nx, i64 level, i64 i0, i64 j0, i64 i1, i64 j1) {
    if (i0 == i1 && j0 == j1) return level;
    if (level < 0 || level >= L) return -2;   /* Python's list indexing: its answer */
    const i64 di = i1 - i0, dj = j1 - j0;
    if (di == 0 || dj == 0) {
        const int d = dj == 1 ? 0 : dj == -1 ? 2 : di == 1 ? 1 : 3;
        return step_link(K, nz, nx, level, i0, j0, d);
    }
    const int d_i = di == 1 ? 1 : 3, d_j = dj == 1 ? 0 : 2;
    const int firsts[2] = {d_i, d_j}, seconds[2] = {d_j, d_i};
    const i64 mi[2] = {i1, i0}, mj[2] = {j0, j1};
    for (int k = 0; k < 2; ++k) {
        const i64 lv = step_link(K, nz, nx, level, i0, j0, firsts[k]);
        if (lv >= 0) {
            const i64 lv2 = step_link(K, nz, nx, lv, mi[k], mj[k], seconds[k]);
            if (lv2 >= 0) return lv2;
        }
    }
    return -1;
}

/* Ground.follow(level, i0, j0, i1, j1) on the ground's int8 links, or None where
 * Python must answer (a level or cell off the grid: its list indexing) */
PyObject *tanktool_ground_follow(PyObject *self, PyObject *args) {
    Py_buffer kb;
    Py_ssize_t L, nz, nx, level, i0, j0, i1, j1;
    if (!PyArg_ParseTuple(args, "y*nnnnnnnn", &kb, &L, &nz, &nx, &level, &i0, &j0, &i1, &j1)) return NULL;
    PyObject *ret = NULL;
    if (!need(&kb, (i64)L * nz * nx * 4, 1, "link")) goto done;
    {
        const int8_t *K = kb.buf;
        i64 lv = -2;
        if (0 <= i0 && i0 < nz && 0 <= j0 && j0 < nx && 0 <= i1 && i1 < nz && 0 <= j1 && j1 < nx) {
            if (i1 - i0 > 1 || i0 - i1 > 1 || j1 - j0 > 1 || j0 - j1 > 1) {
                /* a jump of more than a cell: walked in unit steps, as Python does */
                i64 i = i0, j = j0;
                lv = level;
                while ((i != i1 || j != j1) && lv >= 0) {
                    const i64 si = (i1 > i) - (i1 < i), sj = (j1 > j) - (j1 < j);
                    lv = follow1(K, L, nz, nx, lv, i, j, i + si, j + sj);
                    i += si;
                    j += sj;
                }
            } else {
                lv = follow1(K, L, nz, nx, level, i0, j0, i1, j1);
            }
        }
        if (lv < -1) {
            ret = Py_None;
            Py_INCREF(ret);
        } else {
            ret = PyLong_FromLongLong(lv);
        }
    }
done:
    PyBuffer_Release(&kb);
    return ret;
}

/* layers._walked: from each coarse node (lv, rows[r], cols[c]) k surface steps in each
 * direction along the links, every node on the way ok; out[lv, r, c, d] the level it
 * arrives on, -1 where a step has no link, leaves the grid or meets a node not ok.
 *   link: int8 (L, nz, nx, 4); ok: bool (L, nz, nx); rows, cols: int32; out: int8
 *   (L, R, C, 4), written */
PyObject *tanktool_grid_walk(PyObject *self, PyObject *args) {
    Py_buffer kb, okb, rb, cb, ob;
    Py_ssize_t L, nz, nx, k;
    if (!PyArg_ParseTuple(args, "y*y*y*y*w*nnnn", &kb, &okb, &rb, &cb, &ob, &L, &nz, &nx, &k)) return NULL;
    PyObject *ret = NULL;
    const i64 R = rb.len / 4, C = cb.len / 4;
    if (!need(&kb, (i64)L * nz * nx * 4, 1, "link") || !need(&okb, (i64)L * nz * nx, 1, "ok") ||
        !need(&ob, (i64)L * R * C * 4, 1, "out"))
        goto done;
    {
        const int8_t *K = kb.buf;
        const uint8_t *ok = okb.buf;
        const int32_t *rows = rb.buf, *cols = cb.buf;
        int8_t *out = ob.buf;
        int bad = 0;
        for (i64 r = 0; r < R; ++r)
            if (rows[r] < 0 || rows[r] >= nz) bad = 1;
        for (i64 c = 0; c < C; ++c)
            if (cols[c] < 0 || cols[c] >= nx) bad = 1;
        if (bad) {
            PyErr_SetString(PyExc_ValueError, "grid_walk: a row or column off the grid");
            goto done;
        }
        Py_BEGIN_ALLOW_THREADS
        for (i64 lv = 0; lv < L; ++lv)
            for (i64 r = 0; r < R; ++r)
                for (i64 c = 0; c < C; ++c) {
                    int8_t *o = out + ((lv * R + r) * C + c) * 4;
                    const i64 i0 = rows[r], j0 = cols[c];
                    const int start = ok[(lv * nz + i0) * nx + j0];
                    for (int d = 0; d < 4; ++d) {
                        i64 cur = lv, ci = i0, cj = j0;
                        int alive = start;
                        for (i64 s = 0; s < k && alive; ++s) {
                            const i64 ni = ci + DI_G[d], nj = cj + DJ_G[d];
                            if (ni < 0 || ni >= nz || nj < 0 || nj >= nx) { alive = 0; break; }
                            const int nxt = step_link(K, nz, nx, cur, ci, cj, d);
                            if (nxt < 0) { alive = 0; break; }
                            cur = nxt, ci = ni, cj = nj;
                            if (!ok[(cur * nz + ci) * nx + cj]) alive = 0;
                        }
                        o[d] = alive ? (int8_t)cur : -1;
                    }
                }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&kb);
    PyBuffer_Release(&okb);
    PyBuffer_Release(&rb);
    PyBuffer_Release(&cb);
    PyBuffer_Release(&ob);
    return ret;
}

/* layers._cut_grade: the coarse links rising or falling more than most metres cut (-1),
 * in place; the rise to the neighbour (clamped into the grid) on the level linked to.
 *   link: int8 (L, NZ, NX, 4); heights: float64 (L, NZ, NX) */
PyObject *tanktool_grade_cut(PyObject *self, PyObject *args) {
    Py_buffer kb, hb;
    Py_ssize_t L, NZ, NX;
    double most;
    if (!PyArg_ParseTuple(args, "w*y*nnnd", &kb, &hb, &L, &NZ, &NX, &most)) return NULL;
    PyObject *ret = NULL;
    if (!need(&kb, (i64)L * NZ * NX * 4, 1, "link") || !need(&hb, (i64)L * NZ * NX, 8, "heights")) goto done;
    {
        int8_t *K = kb.buf;
        const double *h = hb.buf;
        Py_BEGIN_ALLOW_THREADS
        for (i64 lv = 0; lv < L; ++lv)
            for (i64 i = 0; i < NZ; ++i)
                for (i64 j = 0; j < NX; ++j) {
                    const double here = h[(lv * NZ + i) * NX + j];
                    for (int d = 0; d < 4; ++d) {
                        int8_t *to = K + ((lv * NZ + i) * NX + j) * 4 + d;
                        if (*to < 0) continue;
                        i64 ti = i + DI_G[d], tj = j + DJ_G[d];
                        ti = ti < 0 ? 0 : ti >= NZ ? NZ - 1 : ti;
                        tj = tj < 0 ? 0 : tj >= NX ? NX - 1 : tj;
                        if (fabs(h[((i64)*to * NZ + ti) * NX + tj] - here) > most) *to = -1;
                    }
                }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&kb);
    PyBuffer_Release(&hb);
    return ret;
}

/* SolidField.visible: out[a, b] = 1 when the segment between points a and b keeps out
 * of the solid, sampled at m / k of the way (m = 1 .. k - 1, k = ceil(length / step) at
 * least 1) as SolidField.inside samples a point (MARGIN up, its voxel), to the bit;
 * pairs farther apart than max_range in (x, z) 0, a point 1 with itself.
 *   solid: bool (nz, nx, ny); points: float64 (n, 3); out: uint8 (n, n), written */
PyObject *tanktool_solid_visible(PyObject *self, PyObject *args) {
    Py_buffer sb, pb, ob;
    Py_ssize_t nz, nx, ny;
    double ox, oz, y0, cs, ch, margin, step, max_range;
    if (!PyArg_ParseTuple(args, "y*y*w*nnndddddddd", &sb, &pb, &ob, &nz, &nx, &ny, &ox, &oz, &y0, &cs, &ch, &margin,
                          &step, &max_range))
        return NULL;
    PyObject *ret = NULL;
    const i64 n = pb.len / 24;
    if (!need(&sb, (i64)nz * nx * ny, 1, "solid") || !need(&pb, 3 * n, 8, "points") || !need(&ob, n * n, 1, "out"))
        goto done;
    {
        const uint8_t *S = sb.buf;
        const double *P = pb.buf;
        uint8_t *V = ob.buf;
        const double ytop = y0 + (double)(ny - 1) * ch, r2 = max_range * max_range;
        Py_BEGIN_ALLOW_THREADS
        for (i64 a = 0; a < n; ++a) {
            V[a * n + a] = 1;
            const double ax = P[3 * a], ay = P[3 * a + 1], az = P[3 * a + 2];
            for (i64 b = a + 1; b < n; ++b) {
                const double dx = P[3 * b] - ax, dy = P[3 * b + 1] - ay, dz = P[3 * b + 2] - az;
                uint8_t vis = 0;
                if (dx * dx + dz * dz <= r2) {
                    double kf = ceil(sqrt(dx * dx + dy * dy + dz * dz) / step);
                    if (!(kf >= 1.0)) kf = 1.0;
                    const i64 k = (i64)kf;
                    vis = 1;
                    for (i64 m = 1; m < k; ++m) {
                        const double t = (double)m / (double)k;
                        const double x = ax + dx * t, y = (ay + dy * t) + margin, z = az + dz * t;
                        const double fj = floor((x - ox) / cs), fi = floor((z - oz) / cs);
                        if (!(fi >= 0.0 && fi < (double)nz && fj >= 0.0 && fj < (double)nx && y < ytop)) continue;
                        double fk = floor((y - y0) / ch);
                        fk = fk < 0.0 ? 0.0 : fk > (double)(ny - 1) ? (double)(ny - 1) : fk;
                        if (S[((i64)fi * nx + (i64)fj) * ny + (i64)fk]) {
                            vis = 0;
                            break;
                        }
                    }
                }
                V[a * n + b] = V[b * n + a] = vis;
            }
        }
        Py_END_ALLOW_THREADS
    }
    ret = Py_None;
    Py_INCREF(ret);
done:
    PyBuffer_Release(&sb);
    PyBuffer_Release(&pb);
    PyBuffer_Release(&ob);
    return ret;
}
