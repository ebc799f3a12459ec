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

/* the rasteriser (_kernels_raster.c) */
PyObject *tanktool_raster(PyObject *self, PyObject *args);

/* the grid (_kernels_grid.c) */
PyObject *tanktool_grid_labels(PyObject *self, PyObject *args);
PyObject *tanktool_grid_links(PyObject *self, PyObject *args);
PyObject *tanktool_grid_runs(PyObject *self, PyObject *args);

/* the levels (_kernels_levels.c) */
PyObject *tanktool_level_votes(PyObject *self, PyObject *args);
PyObject *tanktool_lift_portals(PyObject *self, PyObject *args);

#endif
