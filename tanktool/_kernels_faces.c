/* tanktool._kernels: per-face passes over the model's triangles (see _kernels.c), the
 * same arithmetic in the same order as the numpy code (no fused multiply-adds), so that
 * every flag and height is identical:
 *
 *   walkable_faces(X, Y, Z, f0, f1, f2, cos_slope, flat_ny, walk, flat) -> bool
 *       heightfield.walkable_faces: X, Y, Z float64 (n,) the vertices' coordinates;
 *       f0, f1, f2 int64 (m,) the faces' corners; walk, flat bool (m,) written.  False
 *       (nothing written) when a corner is not a vertex: the numpy code then raises
 *   flat_faces(X, Y, Z, f0, f1, f2, up_min2, flat_ny, height, area) -> k
 *       heightfield.flat_heights' faces: the upward faces of walls._upward_faces whose
 *       normal is within flat_ny of +y, in face order: their centroid heights and
 *       areas written into height, area (float64, m long); -1 for a bad corner
 *
 * Why in C: numpy makes a dozen arrays of a face's coordinates and normal components
 * (~0.3 ms for each pass on Recast's dungeon, 10 k faces, and ~190 bytes a face).
 */
#include "_kernels.h"

/* np.maximum on numbers (a NaN wins, as numpy's does) */
static inline double maxd_(double a, double b) { return isnan(a) || a > b ? a : b; }

/* the corners' edges e1 = v1 - v0, e2 = v2 - v0 and the normal e1 x e2 of face t */
typedef struct {
    double e1x, e1y, e1z, e2x, e2y, e2z, nx, ny, nz;
} Face;

static inline int face_of(const double *X, const double *Y, const double *Z, i64 nv, i64 a, i64 b, i64 c, Face *f) {
    if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv) return 0;
    f->e1x = X[b] - X[a];
    f->e1y = Y[b] - Y[a];
    f->e1z = Z[b] - Z[a];
    f->e2x = X[c] - X[a];
    f->e2y = Y[c] - Y[a];
    f->e2z = Z[c] - Z[a];
    f->nx = f->e1y * f->e2z - f->e1z * f->e2y;
    f->ny = f->e1z * f->e2x - f->e1x * f->e2z;
    f->nz = f->e1x * f->e2y - f->e1y * f->e2x;
    return 1;
}

/* the arguments both passes take: the vertices' X, Y, Z, the faces' corners f0, f1, f2,
 * two numbers, and two output buffers of m items of out_size bytes */
typedef struct {
    Py_buffer X, Y, Z, f0, f1, f2, out1, out2;
    double p1, p2;
    i64 nv;
    Py_ssize_t m;
} FacePass;

static void face_pass_release(FacePass *p) {
    PyBuffer_Release(&p->X);
    PyBuffer_Release(&p->Y);
    PyBuffer_Release(&p->Z);
    PyBuffer_Release(&p->f0);
    PyBuffer_Release(&p->f1);
    PyBuffer_Release(&p->f2);
    PyBuffer_Release(&p->out1);
    PyBuffer_Release(&p->out2);
}

/* 1 with every buffer held and its size checked; 0 with an exception set and none held */
static int face_pass_args(PyObject *args, FacePass *p, Py_ssize_t out_size, const char *out1, const char *out2) {
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*ddw*w*", &p->X, &p->Y, &p->Z, &p->f0, &p->f1, &p->f2, &p->p1, &p->p2,
                          &p->out1, &p->out2))
        return 0;
    p->nv = p->X.len / 8;
    p->m = p->f0.len / 8;
    if (!need(&p->Y, p->nv, 8, "Y") || !need(&p->Z, p->nv, 8, "Z") || !need(&p->f1, p->m, 8, "f1") ||
        !need(&p->f2, p->m, 8, "f2") || !need(&p->out1, p->m, out_size, out1) || !need(&p->out2, p->m, out_size, out2)) {
        face_pass_release(p);
        return 0;
    }
    return 1;
}

PyObject *tanktool_walkable_faces(PyObject *self, PyObject *args) {
    FacePass p;
    if (!face_pass_args(args, &p, 1, "walk", "flat"))
        return NULL;
    const double cos_slope = p.p1, flat_ny = p.p2;
    const i64 nv = p.nv;
    const Py_ssize_t m = p.m;
    int ok = 1;
    {
        const double *x = p.X.buf, *y = p.Y.buf, *z = p.Z.buf;
        const i64 *a = p.f0.buf, *b = p.f1.buf, *c = p.f2.buf;
        char *W = p.out1.buf, *F = p.out2.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t t = 0; t < m && ok; ++t) {
            Face f;
            ok = face_of(x, y, z, nv, a[t], b[t], c[t], &f);
            const double n = sqrt(f.nx * f.nx + f.ny * f.ny + f.nz * f.nz);
            const double cy = n > 0 ? f.ny / n : 0.0;
            W[t] = cy > cos_slope;
            F[t] = cy >= flat_ny;
        }
        Py_END_ALLOW_THREADS
    }
    face_pass_release(&p);
    return PyBool_FromLong(ok);
}

PyObject *tanktool_flat_faces(PyObject *self, PyObject *args) {
    FacePass p;
    if (!face_pass_args(args, &p, 8, "height", "area"))
        return NULL;
    const double up_min2 = p.p1, flat_ny = p.p2;
    const i64 nv = p.nv;
    const Py_ssize_t m = p.m;
    Py_ssize_t k = 0;
    {
        const double *x = p.X.buf, *y = p.Y.buf, *z = p.Z.buf;
        const i64 *a = p.f0.buf, *b = p.f1.buf, *c = p.f2.buf;
        double *H = p.out1.buf, *A = p.out2.buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t t = 0; t < m; ++t) {
            Face f;
            if (!face_of(x, y, z, nv, a[t], b[t], c[t], &f)) {
                k = -1;
                break;
            }
            /* walls._upward_faces: leaning up within UP_NORMAL_MIN */
            if (!(f.ny != 0)) continue;
            const double n2 = f.nx * f.nx + f.ny * f.ny + f.nz * f.nz;
            if (!(f.ny * f.ny >= up_min2 * n2) || !(f.ny > 0)) continue;
            /* flat_heights: np.cross's normal (the same components) over its norm */
            const double ny = f.ny / maxd_(sqrt(n2), 1e-300);
            if (!(ny >= flat_ny)) continue;
            H[k] = (y[a[t]] + y[b[t]] + y[c[t]]) / 3;
            A[k++] = sqrt(n2) / 2;
        }
        Py_END_ALLOW_THREADS
    }
    face_pass_release(&p);
    return PyLong_FromSsize_t(k);
}
