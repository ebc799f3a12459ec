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

PyObject *tanktool_walkable_faces(PyObject *self, PyObject *args) {
    Py_buffer X, Y, Z, f0, f1, f2, walk, flat;
    double cos_slope, flat_ny;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*ddw*w*", &X, &Y, &Z, &f0, &f1, &f2, &cos_slope, &flat_ny, &walk, &flat))
        return NULL;
    const i64 nv = X.len / 8;
    const Py_ssize_t m = f0.len / 8;
    PyObject *ret = NULL;
    int ok = 1;
    if (!need(&Y, nv, 8, "Y") || !need(&Z, nv, 8, "Z") || !need(&f1, m, 8, "f1") || !need(&f2, m, 8, "f2") ||
        !need(&walk, m, 1, "walk") || !need(&flat, m, 1, "flat"))
        goto done;
    {
        const double *x = X.buf, *y = Y.buf, *z = Z.buf;
        const i64 *a = f0.buf, *b = f1.buf, *c = f2.buf;
        char *W = walk.buf, *F = flat.buf;
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
    ret = PyBool_FromLong(ok);
done:
    PyBuffer_Release(&X);
    PyBuffer_Release(&Y);
    PyBuffer_Release(&Z);
    PyBuffer_Release(&f0);
    PyBuffer_Release(&f1);
    PyBuffer_Release(&f2);
    PyBuffer_Release(&walk);
    PyBuffer_Release(&flat);
    return ret;
}

PyObject *tanktool_flat_faces(PyObject *self, PyObject *args) {
    Py_buffer X, Y, Z, f0, f1, f2, height, area;
    double up_min2, flat_ny;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*ddw*w*", &X, &Y, &Z, &f0, &f1, &f2, &up_min2, &flat_ny, &height, &area))
        return NULL;
    const i64 nv = X.len / 8;
    const Py_ssize_t m = f0.len / 8;
    PyObject *ret = NULL;
    Py_ssize_t k = 0;
    if (!need(&Y, nv, 8, "Y") || !need(&Z, nv, 8, "Z") || !need(&f1, m, 8, "f1") || !need(&f2, m, 8, "f2") ||
        !need(&height, m, 8, "height") || !need(&area, m, 8, "area"))
        goto done;
    {
        const double *x = X.buf, *y = Y.buf, *z = Z.buf;
        const i64 *a = f0.buf, *b = f1.buf, *c = f2.buf;
        double *H = height.buf, *A = area.buf;
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
    ret = PyLong_FromSsize_t(k);
done:
    PyBuffer_Release(&X);
    PyBuffer_Release(&Y);
    PyBuffer_Release(&Z);
    PyBuffer_Release(&f0);
    PyBuffer_Release(&f1);
    PyBuffer_Release(&f2);
    PyBuffer_Release(&height);
    PyBuffer_Release(&area);
    return ret;
}
