/* tanktool/_kernels.h: what the kernels' C files share (see _kernels.c). */
#ifndef TANKTOOL_KERNELS_H
#define TANKTOOL_KERNELS_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef int64_t i64;

static inline int need(Py_buffer *b, Py_ssize_t items, Py_ssize_t itemsize, const char *name) {
    if (b->len != items * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd bytes, got %zd", name, items * itemsize, b->len);
        return 0;
    }
    return 1;
}

static inline i64 min64(i64 a, i64 b) { return a < b ? a : b; }
static inline i64 max64(i64 a, i64 b) { return a > b ? a : b; }

/* the chamfer relaxation (chamfer in _kernels.c, chamfer_near in _kernels_surface.c) */

/* the value at span a, 0 off the edge (a < 0: the sentinel of chamfer_clearance) */
static inline int32_t at(const int32_t *dist, i64 a) { return a < 0 ? 0 : dist[a]; }

/* one relaxation of span s: straight steps cost 2, diagonal ones (a straight link,
 * then the next direction's link from there, either way round) 3 */
static inline int32_t relax(const int32_t *L, const int32_t *dist, Py_ssize_t s, int32_t v) {
    const int32_t *l = L + 4 * s;
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

/* the rasteriser (_kernels_raster.c) */
PyObject *tanktool_raster_merge(PyObject *self, PyObject *args);

/* the faces (_kernels_faces.c) */
PyObject *tanktool_walkable_faces(PyObject *self, PyObject *args);
PyObject *tanktool_flat_faces(PyObject *self, PyObject *args);

/* the grid (_kernels_grid.c) */
PyObject *tanktool_grid_labels(PyObject *self, PyObject *args);
PyObject *tanktool_grid_links(PyObject *self, PyObject *args);
PyObject *tanktool_grid_runs(PyObject *self, PyObject *args);

/* the open spans, their clearance and levels (_kernels_surface.c) */
PyObject *tanktool_open_spans(PyObject *self, PyObject *args);
PyObject *tanktool_snap_heights(PyObject *self, PyObject *args);
PyObject *tanktool_flat_floor_of(PyObject *self, PyObject *args);
PyObject *tanktool_scatter_layers(PyObject *self, PyObject *args);
PyObject *tanktool_level_votes(PyObject *self, PyObject *args);
PyObject *tanktool_lift_portals(PyObject *self, PyObject *args);
PyObject *tanktool_chamfer_near(PyObject *self, PyObject *args);

/* the ground under a tank (_kernels_ground.c) */
PyObject *tanktool_ground_tilt(PyObject *self, PyObject *args);
PyObject *tanktool_ground_height(PyObject *self, PyObject *args);
PyObject *tanktool_ground_follow(PyObject *self, PyObject *args);
PyObject *tanktool_grid_walk(PyObject *self, PyObject *args);
PyObject *tanktool_grade_cut(PyObject *self, PyObject *args);
PyObject *tanktool_solid_visible(PyObject *self, PyObject *args);

/* the agents' paths (_kernels_path.c) */
PyObject *tanktool_astar_layered(PyObject *self, PyObject *args);

#endif
